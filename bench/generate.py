"""Prompt -> finished scene for a 10 s motion: a cold start against a warm call, same run.

cold (the baseline): a new process runs ``python -m shapemove demo`` (import torch/transformers/
bpy, load the models, generate, build the rig, render the preview strip, save the .blend);
warm: the same work a second time in one process with the models already loaded (what the
Blender extension's worker does for every prompt after the first). Reports seconds and cold/warm.
Uses the embedded default model, or a tiny one trained on the spot when it is not built
(``bench/inputs.py``). Times are the best of the repeats (the machine is shared).
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PROMPT = "a person jogs forward and waves"
SHAPE = "a tall, heavy-set man"
SECONDS = 10.0


def _cold(model: Path, out: Path, frames: int) -> float:
    cmd = [sys.executable, "-m", "shapemove", "demo", "--prompt", PROMPT, "--shape-text", SHAPE, "--seconds",
           str(SECONDS), "--model", str(model), "--out", str(out), "--frames", str(frames)]
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True,
                         env={**os.environ, "TQDM_DISABLE": "1"})
    dt = time.perf_counter() - t0
    if res.returncode != 0 or not (out / "shapemove.blend").is_file():
        raise RuntimeError(f"demo failed ({res.returncode}): {res.stderr.strip()[-800:]}")
    return dt


def _warm_call(gen, out: Path, frames: int, seed: int) -> tuple[float, float, int]:
    """(generate seconds, scene seconds, frames) of one prompt with loaded models."""
    from ..core.scene.motion_file import save_motion
    from ..shapemove_addon.headless import build_scene_file

    t0 = time.perf_counter()
    motion = gen.generate(PROMPT, SHAPE, seconds=SECONDS, seed=seed)
    save_motion(out / "motion.npz", motion)
    t1 = time.perf_counter()
    build_scene_file(motion, gen.body, out / "shapemove.blend", out / "preview.png", frames=frames)
    return t1 - t0, time.perf_counter() - t1, motion.num_frames


def run(quick: bool = False) -> dict:
    from ..core.generation.generate import Generator
    from .inputs import model_dir

    model, what = model_dir()
    frames = 2 if quick else 5
    repeats = 1 if quick else 2
    print(f"model: {what} ({model}); {SECONDS:g} s motion, preview strip of {frames} frames")
    with tempfile.TemporaryDirectory(prefix="shapemove_bench_") as tmp:
        tmp = Path(tmp)
        cold = min(_cold(model, tmp / f"cold{i}", frames) for i in range(repeats))
        t0 = time.perf_counter()
        gen = Generator(model)
        load = time.perf_counter() - t0
        first = _warm_call(gen, tmp / "warm0", frames, seed=0)  # first call: bpy import, caches
        warm = [_warm_call(gen, tmp / f"warm{i + 1}", frames, seed=i + 1) for i in range(repeats + 1)]
    best = min(warm, key=lambda w: w[0] + w[1])
    warm_s = best[0] + best[1]
    print(f"cold: new process, `demo` end to end      {cold:6.2f} s (baseline)")
    print(f"      (in-process: model load {load:.2f} s, first call {first[0] + first[1]:.2f} s)")
    print(f"warm: generate {best[0]:.2f} s + scene {best[1]:.2f} s = {warm_s:6.2f} s  ({best[2]} frames)")
    print(f"generate_cold_over_warm: {cold / warm_s:.1f}x")
    return {"generate_cold_s": cold, "generate_warm_s": warm_s, "generate_warm_motion_s": best[0],
            "generate_warm_scene_s": best[1], "generate_model_load_s": load, "generate_cold_over_warm": cold / warm_s}
