"""Does an asked distance hold on every body? On the default model, "a man walks 3 metres forward"
on bodies the shape words make (tall, short, heavy, slim, child-sized, old), seeds 0 and 1:
the distance the pelvis ends from where it started in a straight line (``stop_words.from_start``)
as a prompt of its own (the length the model gives it) and as a timeline's first segment (4 s,
then "he waves" 2 s), and how far the pelvis drifts while the wave stands (its largest distance
from where the wave starts). Goal: within 5 % of the distance on every body, no drift (under 0.1
m) while standing. Deterministic."""
from __future__ import annotations

import numpy as np

GOAL = 0.05
DRIFT = 0.1   # m
PROMPT, METRES = "a man walks 3 metres forward", 3.0
BODIES = (None, "a 6 ft 2, 200 lb man", "a tall heavy-set man", "a short, slim woman", "a 190 cm tall woman",
          "a 5 ft 1 woman", "a short, heavy man", "a tall, thin man", "a 4 ft 6 child", "an old man")


def run(quick: bool = False) -> dict:
    from ..core.errors import ShapeMoveError
    from ..core.generation.generate import Generator, Request
    from ..core.generation.sequence import generate_sequence
    from ..core.generation.stop_words import from_start
    from .inputs import model_dir

    model, what = model_dir()
    gen = Generator(model)
    print(f"model: {what} ({model})")
    rows = []
    for shape in (BODIES[:3] if quick else BODIES):
        for seed in ((0,) if quick else (0, 1)):
            try:
                alone = gen.generate_batch([Request(PROMPT, shape_text=shape, seed=seed)])[0]
                line = generate_sequence(gen, [(PROMPT, 4.0), ("he waves", 2.0)], shape_text=shape, seed=seed)
            except ShapeMoveError as e:
                print(f"{shape!r}: refused ({e})")
                continue
            went = float(from_start(alone.joints)[-1])
            cut = int(line.segment_bounds[1, 0]) if line.segment_bounds is not None else line.num_frames
            walked = float(from_start(line.joints[:cut])[-1])
            stand = np.asarray(line.joints[cut:, 0, :], np.float64)[:, [0, 2]]
            drift = float(np.linalg.norm(stand - stand[0], axis=1).max()) if len(stand) else 0.0
            ok = abs(went / METRES - 1) <= GOAL and abs(walked / METRES - 1) <= GOAL and drift <= DRIFT
            rows.append({"body": shape or "average", "seed": seed, "alone_m": went, "timeline_m": walked,
                         "drift_m": drift, "ok": ok})
            print(f"{shape or 'average'} / seed {seed}: alone {went:.2f} m ({went / METRES:.3f}x), timeline "
                  f"{walked:.2f} m ({walked / METRES:.3f}x), drift while waving {drift:.2f} m"
                  f"{'' if ok else '  outside'}", flush=True)
    off = [r for r in rows if not r["ok"]]
    print(f"{len(rows)} bodies x seeds: {len(off)} outside {GOAL:.0%} or drifting over {DRIFT} m")
    return {"distances": {"rows": rows, "outside": len(off)}}
