"""Stance slide, penetrate and float of planted walks on one or more model folders (issue #24: the
foot roll in ``body/plant.py``). For each model and seed: "a person walks forward", 4 s; that walk
along an S-curve (3 m long, +-0.6 m, not cropped); that walk at
double speed (``time_warp``); optionally the walk loop.

    python tools/foot_roll_slide.py --model weights/default --model /tmp/m_ft2 [--seeds 0 1 2 3] [--loop] [--json out.json]

A model folder is ``weights/default``'s layout (``savae.pt``, ``t5/``, ``tma/``); to try another
decoder with the shipped T5, copy the folder, replace ``savae.pt`` and its entry in
``manifest.json``. Per motion: stance slide (``eval.physics.stance_slide`` on the Motion's joints
and contacts, mm per frame; heels and balls apart), the lowest mesh point (``soles.GroundProbe``):
the deepest frame (cm), penetrate and float (``eval.physics``, cm over frames beyond 5 mm), the
IK error of the plant (cm) and the share of heel-contact frames released by the roll."""
from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np


def s_path() -> np.ndarray:
    t = np.linspace(0, 1, 40)
    return np.stack([0.6 * np.sin(2 * np.pi * t), 3.0 * t], 1)


def measure(m, body) -> dict:
    """One planted Motion -> its slide, ground and contact numbers."""
    from shapemove.core.body.soles import GroundProbe
    from shapemove.core.eval.physics import floating, penetrate, stance_slide
    from shapemove.core.geometry.rotations import axis_angle_to_matrix

    c = np.asarray(m.contacts).astype(bool)
    mm, pct = stance_slide(m.joints, c)
    heel = c.copy()
    heel[:, 2:] = False
    ball = c.copy()
    ball[:, :2] = False
    _, _, low = GroundProbe(body, m.betas).lowest(axis_angle_to_matrix(np.asarray(m.poses, np.float64)), m.transl)
    return {"slide_mm": mm.value, "slide_pct": pct.value, "heel_mm": stance_slide(m.joints, heel)[0].value,
            "ball_mm": stance_slide(m.joints, ball)[0].value, "lowest_cm": float(low.min() * 100),
            "penetrate_cm": penetrate(low).value, "penetrate_frames": penetrate(low).count,
            "float_cm": floating(low).value, "float_frames": floating(low).count,
            "ik_error_cm": float(m.ik_error_cm) if m.ik_error_cm is not None else float("nan"),
            "heel_frames": int(c[:, :2].sum()), "ball_frames": int(c[:, 2:].sum()), "frames": int(len(c))}


def run_model(model: str, seeds, loop: bool) -> dict:
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.path_follow import follow_path
    from shapemove.core.generation.time_warp import time_warp

    gen = Generator(model)
    out: dict = {}
    for seed in seeds:
        walk = gen.generate_batch([Request("a person walks forward", seconds=4, seed=seed)])[0]
        rows = {"walk": walk, "s_curve": follow_path(walk, gen.body, s_path(), crop=False),
                "speed_2x": time_warp(walk, gen.body, speed=2.0)}
        if loop:
            from shapemove.core.generation.loop import generate_loop

            rows["loop"] = generate_loop(gen, Request("a person walks forward", seed=seed))
        for name, m in rows.items():
            r = measure(m, gen.body)
            out.setdefault(name, {})[seed] = r
            print(f"{model} seed {seed} {name:8s}: slide {r['slide_mm']:.2f} mm/frame (heel {r['heel_mm']:.2f}, "
                  f"ball {r['ball_mm']:.2f}), lowest {r['lowest_cm']:.2f} cm, penetrate {r['penetrate_cm']:.2f} cm "
                  f"x{r['penetrate_frames']}, float {r['float_cm']:.2f} cm x{r['float_frames']}, "
                  f"IK {r['ik_error_cm']:.2f} cm, heel/ball contact frames {r['heel_frames']}/{r['ball_frames']}",
                  flush=True)
    return out


def summary(results: dict) -> str:
    lines = ["| model | motion | slide mm/frame (seeds) | heel | ball | deepest cm | float cm | IK cm |",
             "|---|---|---|---|---|---|---|---|"]
    for model, res in results.items():
        for name, per in res.items():
            v = lambda k: np.array([r[k] for r in per.values()])   # noqa: E731
            s = v("slide_mm")
            lines.append(f"| {model} | {name} | {s.min():.2f}-{s.max():.2f} (mean {s.mean():.2f}) | "
                         f"{v('heel_mm').mean():.2f} | {v('ball_mm').mean():.2f} | {v('lowest_cm').min():.2f} | "
                         f"{v('float_cm').mean():.2f} | {v('ik_error_cm').mean():.2f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", action="append", required=True, help="model folder (repeat to compare)")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3])
    ap.add_argument("--loop", action="store_true", help="also the walk loop of each seed")
    ap.add_argument("--json", help="write every number here")
    a = ap.parse_args(argv)
    from shapemove.core.torch_threads import one_torch_thread

    t0 = time.perf_counter()
    with one_torch_thread():
        results = {m: run_model(m, a.seeds, a.loop) for m in a.model}
    print(summary(results))
    print(f"{time.perf_counter() - t0:.0f} s")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(results, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
