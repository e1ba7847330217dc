"""Long takes (issue 28): peak memory and time of ``retarget`` (naive and through the SA-VAE) and
of ``data build`` on a take of 1, 3 and 10 minutes at 30 and 120 fps.

The takes are built from a short real Bandai walk (``long_take_input.py``). Each run is the real
command in a fresh process (``python -m shapemove ...``) that reports its own peak resident memory
(``ru_maxrss``) and CPU seconds (user + system) when it ends: on a shared machine wall seconds
depend on the neighbours (printed too), CPU seconds much less, so the time goal is judged on
them. Goals: peak <= 1.5 GB
whatever the length; time <= 1.1x linear: ``x_linear`` = t(10 min) / (10 t(1 min)) (start-up is
paid once, so a linear pipeline is below 1) and ``slope_ratio`` = (seconds per extra minute from 3 to
10 min) / (from 1 to 3 min): 1 when the cost of a minute does not grow with the take; both <= 1.1.
``--quick``: 0.5, 1 and 2 minutes at 30 fps, naive only.
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ..core.io.archive import mocap_root
from .long_take_input import walk_path, write_long_take

GOAL_MB = 1536
GOAL_LINEAR = 1.1
PEAK_WRAPPER = """
import resource, runpy, sys
sys.argv = ["shapemove"] + sys.argv[1:]
code = 0
try:
    runpy.run_module("shapemove", run_name="__main__")
except SystemExit as exc:
    code = exc.code or 0
u = resource.getrusage(resource.RUSAGE_SELF)
# VmHWM: this program's own peak (ru_maxrss would carry a large parent's size over fork + exec)
hwm = [ln.split()[1] for ln in open("/proc/self/status") if ln.startswith("VmHWM:")]
print("PEAK_KB", hwm[0] if hwm else u.ru_maxrss, "CPU_S", u.ru_utime + u.ru_stime, file=sys.stderr)
sys.exit(code)
"""


def measure(args: list[str]) -> tuple[float, float, float]:
    """(wall seconds, CPU seconds, peak MB) of ``python -m shapemove ARGS`` in a fresh process."""
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", PEAK_WRAPPER, *args], capture_output=True, text=True,
                       env={**os.environ, "TQDM_DISABLE": "1"})
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(args[:1])} failed ({r.returncode}): {r.stderr.strip()[-800:]}")
    tail = r.stderr.split("PEAK_KB")[-1].split()
    return dt, float(tail[2]), int(tail[0]) / 1024


def _runs(take: Path, out: Path, method: str) -> list[str]:
    """The command line of one run: ``data build`` on a folder holding only the take, or ``retarget``."""
    if method == "build":
        src = out.with_suffix("")
        src.mkdir(exist_ok=True)
        link = src / take.name
        if not link.exists():
            link.symlink_to(take)
        return ["data", "build", "--source", str(src), "--out", str(out.with_name(out.stem + "_built")),
                "--augment-share", "0"]
    return ["retarget", "--motion", str(take), "--betas", "1.5,-0.5", "--out", str(out)] + (
        ["--naive"] if method == "naive" else [])


def _check_output(out: Path, method: str) -> None:
    """A run counts only when it made its output: the motion file, or the built clip (no failure)."""
    if method != "build":
        if not out.is_file():
            raise RuntimeError(f"retarget wrote no {out}")
        return
    report = out.with_name(out.stem + "_built") / "build_report.txt"
    text = report.read_text() if report.is_file() else ""
    if "clips built: 1 " not in text or "failed: 0" not in text:
        raise RuntimeError(f"data build did not build the take: {text.strip()[-400:]}")


def _linearity(times: dict) -> tuple[float, float]:
    m = sorted(times)
    t1, t3, t10 = (times[k] for k in m)
    x_linear = t10 / (m[2] / m[0] * t1)
    slope_ratio = ((t10 - t3) / (m[2] - m[1])) / ((t3 - t1) / (m[1] - m[0]))
    return x_linear, slope_ratio


def run(quick: bool = False) -> dict:
    minutes = (0.5, 1.0, 2.0) if quick else (1.0, 3.0, 10.0)
    plans = [(30.0, "naive")] if quick else [(30.0, "naive"), (30.0, "savae"), (120.0, "naive"), (120.0, "savae"),
                                             (30.0, "build")]
    walk = walk_path(mocap_root())
    results: dict = {}
    with tempfile.TemporaryDirectory(prefix="shapemove_long_take_") as tmp:
        tmp = Path(tmp)
        for fps, method in plans:
            times, walls, peaks = {}, {}, {}
            for m in minutes:
                take = tmp / f"walk_{m:g}min_{fps:g}fps.bvh"
                if not take.exists():
                    write_long_take(walk, take, m * 60.0, fps)
                out = tmp / f"out_{method}_{m:g}_{fps:g}.npz"
                dt, cpu, peak = measure(_runs(take, out, method))
                _check_output(out, method)
                times[m], walls[m], peaks[m] = cpu, dt, peak
                print(f"  {method:5s} {fps:3.0f} fps {m:4g} min: {cpu:6.1f} CPU s ({dt:6.1f} s wall), peak {peak:6.0f} MB"
                      f" ({take.stat().st_size / 2**20:.0f} MB file)", flush=True)
            x_lin, slope = _linearity(times)
            ok = max(peaks.values()) <= GOAL_MB and x_lin <= GOAL_LINEAR and slope <= GOAL_LINEAR
            print(f"  {method} {fps:g} fps: peak {max(peaks.values()):.0f} MB (goal <= {GOAL_MB}), "
                  f"x{x_lin:.2f} linear, slope ratio {slope:.2f} (goals <= {GOAL_LINEAR}; CPU seconds) -> "
                  f"{'meets' if ok else 'MISSES'} the goals")
            key = f"long_take_{method}_{fps:g}fps"
            results[key] = {"minutes": list(minutes), "cpu_seconds": [round(times[m], 2) for m in minutes],
                            "wall_seconds": [round(walls[m], 2) for m in minutes],
                            "peak_mb": [round(peaks[m]) for m in minutes], "x_linear": round(x_lin, 3),
                            "slope_ratio": round(slope, 3), "meets_goals": ok}
    return results
