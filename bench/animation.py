"""The figures of docs/animation.md on the default model: loop seams, in place drift, an S-curve
path, speed 0.5x / 2x, timeline boundaries and the TMA judge of each segment. Deterministic
(seeded); each row says which prompt and seed."""
from __future__ import annotations

import numpy as np

from .timeline import TIMELINE, s_curve


def _slide(m) -> float:
    from ..core.eval.physics import stance_slide

    return stance_slide(m.joints, m.contacts)[0].value


def run(quick: bool = False) -> dict:
    from ..core.generation.generate import Generator, Request
    from ..core.generation.in_place import in_place, root_drift
    from ..core.generation.loop import generate_loop, seam_report
    from ..core.generation.path_follow import follow_path, path_report
    from ..core.generation.sequence import boundary_report, generate_sequence, segment_scores
    from ..core.generation.time_warp import time_warp
    from .inputs import model_dir

    model, what = model_dir()
    gen = Generator(model)
    print(f"model: {what} ({model})")
    out: dict = {"loop": {}, "path": {}, "speed": {}, "timeline": []}
    seeds = (0,) if quick else (0, 1, 2)
    for prompt in ("a person walks forward", "a person jogs forward", "a person waves"):
        for seed in seeds:
            m = generate_loop(gen, Request(prompt, seed=seed))
            r = {**seam_report(m), "slide_mm": _slide(m)}
            out["loop"][f"{prompt} / seed {seed}"] = r
            print(f"loop  {prompt!r} seed {seed}: {r['frames']} frames, worst jump {r['jump_ratio']:.2f}x its mean step, "
                  f"advance {r['advance_m']:.2f} m/cycle vs speed {100 * r['advance_vs_speed']:.2f} % off, "
                  f"stance slide {r['slide_mm']:.2f} mm/frame")
    for seed in seeds:
        walk = gen.generate_batch([Request("a person walks forward", seconds=6, seed=seed)])[0]
        ip = in_place(walk)
        print(f"in place seed {seed}: drift {100 * root_drift(walk):.0f} cm -> {100 * root_drift(ip):.2f} cm")
        out.setdefault("in_place", {})[seed] = {"before_m": root_drift(walk), "after_m": root_drift(ip)}
        for width in (0.5, 1.0):
            path = s_curve(4.0, width)
            m = follow_path(walk, gen.body, path)
            r = {**path_report(m, path), "slide_mm": _slide(m), "slide_before_mm": _slide(walk)}
            out["path"][f"S {width:g} m wide / seed {seed}"] = r
            print(f"path  S-curve 4 m long, +-{width:g} m, seed {seed}: root {100 * r['root_mean_m']:.1f} cm mean, "
                  f"{100 * r['root_max_m']:.1f} cm max; facing {r['facing_mean_deg']:.1f} deg mean, "
                  f"{r['facing_max_deg']:.1f} max; slide {r['slide_mm']:.2f} mm/frame (generated: {r['slide_before_mm']:.2f})")
        for speed in (0.5, 2.0):
            m = time_warp(walk, gen.body, speed=speed)
            out["speed"][f"{speed:g}x / seed {seed}"] = {"frames": m.num_frames, "want": round(walk.num_frames / speed),
                                                          "slide_mm": _slide(m)}
            print(f"speed {speed:g}x seed {seed}: {walk.num_frames} -> {m.num_frames} frames "
                  f"(want {round(walk.num_frames / speed)}), slide {_slide(m):.2f} mm/frame")
    for seed in seeds:
        m = generate_sequence(gen, list(TIMELINE), seed=seed)
        b = boundary_report(m)
        s = segment_scores(gen, m)
        hit = (s.argmax(0) == np.arange(len(TIMELINE))).tolist()
        out["timeline"].append({"seed": seed, **b, "judged_right": hit})
        print(f"timeline seed {seed}: boundary jumps {', '.join(f'{r:.2f}' for r in b['ratios'])} x p99 step; "
              f"segments judged as asked: {hit}")
    return {"animation": out}
