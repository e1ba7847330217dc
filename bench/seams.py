"""Timeline seams on the default model: 20 timelines of gaits and gestures, each boundary's worst
joint step (within ``seam_pace.SEAM`` frames of it) over that joint's 99th percentile step inside
the segments, for the played motion (paced seams, planted) of the timeline of finished segments
(captured takes on, ``stitched_timeline.py``) and of the timeline of codes (off), and for the
latter the decoded track of the same codes (no pacing, no planting). Goal: every boundary of the
played motion <= 1.5. Deterministic (seed 0 for the first timeline, +1 for each next)."""
from __future__ import annotations

import numpy as np

GOAL = 1.5
WALK, JOG, RUN = "a person walks forward", "a person jogs forward", "a person runs forward"
WAVE, RAISE, PUNCH = "a person waves with the right hand", "a person raises the left hand", "a person punches"
TIMELINES = [
    ((WALK, 3), (WAVE, 3)),
    ((WAVE, 2), (WALK, 3)),
    ((RUN, 2), (WAVE, 2)),
    ((JOG, 3), (RAISE, 2)),
    ((WALK, 2), (RUN, 2), (WALK, 2)),
    (("a person jumps", 2), (WALK, 3)),
    ((WALK, 3), ("a person sits down", 3)),
    (("a person sits down", 3), (WAVE, 2)),
    ((PUNCH, 2), (WALK, 3)),
    ((WALK, 3), (PUNCH, 2)),
    (("a person kicks", 2), (JOG, 3)),
    ((RUN, 3), ("a person stands still", 2)),
    (("a person walks backwards", 3), (WAVE, 2)),
    ((WALK, 2), ("a person turns around", 2), (WALK, 2)),
    ((JOG, 2), ("a person jumps", 2)),
    ((RAISE, 2), (RUN, 3)),
    (("a person does a squat", 3), (WALK, 3)),
    (("a person sidesteps to the left", 3), (WAVE, 2)),
    ((WAVE, 2), (PUNCH, 2), (WAVE, 2)),
    (("a person walks in a circle", 4), ("a person kicks", 2)),
]


def run(quick: bool = False) -> dict:
    from ..core.generation.generate import Generator
    from ..core.generation.seam_pace import seam_steps
    from ..core.generation.sequence import boundary_report, generate_sequence
    from ..core.generation.track import decoded_track
    from .inputs import model_dir

    model, what = model_dir()
    gen = Generator(model)
    print(f"model: {what} ({model})")
    out = {"goal": GOAL}
    for kind, captured in (("finished segments", True), ("codes", False)):   # stitched_timeline.py / sequence.py
        gen.set_captured(captured)
        rows, played, decoded = [], [], []
        for i, segs in enumerate(TIMELINES[:4] if quick else TIMELINES):
            m = generate_sequence(gen, [list(s) for s in segs], seed=i)
            r = boundary_report(m)
            raw = []
            if m.num_tokens:   # the decoded track of the same codes, unpaced and unplanted
                track, _ = decoded_track([int(t) for t in m.tokens], gen.vae, gen.body, m.betas)
                raw = seam_steps(track.joints, r["boundaries"])
            played += r["ratios"]
            decoded += raw
            rows.append({"prompts": [p for p, _ in segs], "seed": i, "played": r["ratios"], "decoded": raw})
            print(f"[{kind}] {' -> '.join(p for p, _ in segs)} (seed {i}): played "
                  f"{', '.join(f'{x:.2f}' for x in r['ratios'])}"
                  + (f"; decoded {', '.join(f'{x:.2f}' for x in raw)}" if raw else "") + " x p99 step", flush=True)
        worst = float(max(played))
        print(f"[{kind}] {len(played)} boundaries of {len(rows)} timelines: played worst {worst:.2f}, median "
              f"{np.median(played):.2f} (goal <= {GOAL:g})"
              + (f"; decoded worst {max(decoded):.2f}, median {np.median(decoded):.2f}" if decoded else "")
              + f"; {sum(x > GOAL for x in played)} over the goal")
        out["stitched" if captured else "codes"] = {"timelines": rows, "played_worst": worst,
                                                     "decoded_worst": float(max(decoded)) if decoded else None}
    gen.set_captured(True)
    return {"seams": out}
