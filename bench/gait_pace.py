"""Do plain gait prompts go at their gait's typical pace? On the default model, a few plain
prompts per gait (walk, jog, run: no pace, speed, distance, steps or course asked) x 5 seeds on the
average body, with captured takes competing (the default) and without them (``--no-library``):
per gait, the median root speed (``eval.gait.mean_speed``: the pelvis's horizontal path over the
motion's length) against the gait's typical speed (``generation/typical_pace.py``: the median of
the training data's normal-style captures of it on the average body). Goal: within 0.95-1.05x.
Deterministic (seeds 0-4)."""
from __future__ import annotations

import numpy as np

GOAL = (0.95, 1.05)
PROMPTS = {
    "walk": ["a person walks forward", "a man walks", "someone is walking forward"],
    "jog": ["a person jogs", "a woman jogs forward", "someone is jogging"],
    "run": ["a person runs forward", "a man runs", "someone is running forward"],
}
SEEDS = range(5)


def run(quick: bool = False) -> dict:
    from ..core.eval.gait import mean_speed
    from ..core.generation.generate import Generator, Request
    from ..core.generation.typical_pace import load_typical_speeds
    from .inputs import model_dir

    model, what = model_dir()
    gen = Generator(model)
    typical = load_typical_speeds(model)
    print(f"model: {what} ({model}); typical speeds {typical or 'none (no typical_pace.json)'}")
    seeds = range(2) if quick else SEEDS
    out = {}
    for library in (True, False):
        gen.set_captured(library)
        label = "captured takes on" if library else "captured takes off"
        for gait, prompts in PROMPTS.items():
            prompts = prompts[:1] if quick else prompts
            speeds = [mean_speed(m.joints) for p in prompts
                      for m in gen.generate_batch([Request(p, seed=s) for s in seeds])]
            med = float(np.median(speeds))
            want = typical.get(gait)
            ratio = med / want if want else float("nan")
            ok = want is not None and GOAL[0] <= ratio <= GOAL[1]
            print(f"{label}: {gait}: median {med:.2f} m/s over {len(speeds)} motions (spread "
                  f"{min(speeds):.2f}-{max(speeds):.2f}); typical {want if want else float('nan'):.2f}: "
                  f"{ratio:.2f}x{'' if ok else '  outside ' + '-'.join(f'{g:g}' for g in GOAL)}", flush=True)
            out[f"{gait}{'' if library else '_no_library'}"] = {"median": med, "typical": want, "ratio": ratio,
                                                                 "speeds": [float(s) for s in speeds]}
    gen.set_captured(True)
    return {"gait_pace": out}
