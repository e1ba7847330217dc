"""Run motion-file loads under a time and memory limit, each in its own process (not a test module).

``run_limited(cases, timeout_s, mem_bytes)`` starts ONE helper Python (this file as a script) that
imports the readers once and forks a child per case; the child sets RLIMIT_AS (address space:
what the child had at fork + ``mem_bytes``) and an alarm, loads the file with
``load_mocap`` + ``mocap_to_smpl22`` and reports. Returns, per case, a dict:
``outcome`` ("ok" | "ShapeMoveError" | "timeout" | "killed" | the name of any other exception),
``message``, ``seconds`` and ``max_rss`` (bytes, the child's peak resident memory).

case = {"path": str, "asf": str | None}
"""
from __future__ import annotations

import json
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def run_limited(cases: list[dict], timeout_s: float = 30.0, mem_bytes: int = 1 << 30) -> list[dict]:
    proc = subprocess.run([sys.executable, str(Path(__file__).resolve()), str(timeout_s), str(mem_bytes)],
                          input=json.dumps(cases), capture_output=True, text=True,
                          timeout=60 + len(cases) * (timeout_s + 1))
    if proc.returncode != 0:
        raise RuntimeError(f"limited_run helper failed ({proc.returncode}): {proc.stderr[-2000:]}")
    return [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]


def _vm_bytes() -> int:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")


def _load(case: dict):
    import numpy as np

    from shapemove.core.io.asf_amc import load_amc
    from shapemove.core.io.mocap import load_mocap, mocap_to_smpl22

    m = load_amc(case["path"], asf=case["asf"]) if case.get("asf") else load_mocap(case["path"])
    if not np.all(np.isfinite(m.positions)):
        raise AssertionError("loaded positions are not finite")
    mo = mocap_to_smpl22(m)
    if not np.all(np.isfinite(mo.joints)):
        raise AssertionError("SMPL22 joints are not finite")


def _child(case: dict, timeout_s: float, mem_bytes: int, wfd: int) -> None:
    from shapemove.core.errors import ShapeMoveError

    limit = _vm_bytes() + mem_bytes
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    signal.alarm(max(1, int(timeout_s)))  # default action: the child dies, the parent sees SIGALRM
    try:
        _load(case)
        out = {"outcome": "ok", "message": ""}
    except ShapeMoveError as exc:
        out = {"outcome": "ShapeMoveError", "message": str(exc)[:300]}
    except BaseException as exc:  # noqa: BLE001  anything else is a finding
        out = {"outcome": type(exc).__name__, "message": str(exc)[:300]}
    os.write(wfd, json.dumps(out).encode())
    os._exit(0)


def _main() -> None:
    timeout_s, mem_bytes = float(sys.argv[1]), int(sys.argv[2])
    cases = json.loads(sys.stdin.read())
    # import everything the loads need before forking: children only do the work
    import shapemove.core.io.asf_amc  # noqa: F401
    import shapemove.core.io.bvh  # noqa: F401
    import shapemove.core.io.mocap  # noqa: F401
    import shapemove.core.io.rig_map  # noqa: F401
    import shapemove.core.io.tpose  # noqa: F401
    try:
        import shapemove.core.io.deepmimic  # noqa: F401
    except ImportError:
        pass
    for case in cases:
        r, w = os.pipe()
        t0 = time.perf_counter()
        pid = os.fork()
        if pid == 0:
            os.close(r)
            _child(case, timeout_s, mem_bytes, w)
        os.close(w)
        data = b""
        while chunk := os.read(r, 65536):
            data += chunk
        os.close(r)
        _, status, usage = os.wait4(pid, 0)
        res = json.loads(data) if data else {"outcome": "killed", "message": f"wait status {status}"}
        if os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGALRM:
            res = {"outcome": "timeout", "message": f"over {timeout_s} s"}
        res.update(path=case["path"], seconds=time.perf_counter() - t0, max_rss=usage.ru_maxrss * 1024)
        print(json.dumps(res), flush=True)


if __name__ == "__main__":
    _main()
