"""Does planting add leaps? On the default model, 40 prompts (courses, squats, jumps, runs) x 3
bodies x 2 seeds: per motion, each joint's largest step in one frame of the planted motion over
the same joint's largest step in the decoded track it was planted from (``network_joints``); the
worst joint's ratio. Goal: <= 1.5 for every motion. Deterministic (seeds 0 and 1)."""
from __future__ import annotations

import numpy as np

GOAL = 1.5
BODIES = (None, "a 6 ft 2, 200 lb man", "a short, slim woman")
PROMPTS = [
    "a man walks in a circle", "a man walks backwards in a circle", "a person walks in a figure eight",
    "someone paces back and forth", "a woman walks in a zigzag", "a person jogs in a circle",
    "a man runs in a circle", "a person walks diagonally to the right", "someone walks up and down the room",
    "a person walks sideways to the left",
    "a person does four squats", "a man does three squats", "someone squats down and stands up",
    "a woman does deep squats", "a person squats twice", "a person does five squats slowly",
    "a man squats and holds it", "a person does squats in place", "someone does a squat then jumps",
    "a person squats down to pick something up",
    "a person jumps forward twice", "someone does four jumps in place", "a man jumps up high",
    "a person hops on one leg", "she does five jumping jacks", "a person jumps over an obstacle",
    "a man does a long jump", "a child jumps up and down", "a person jumps to the left",
    "someone skips forward",
    "a person runs forward", "a man sprints", "a woman jogs forward", "a person runs and stops",
    "someone runs ten meters and stops", "a person jogs in place", "a man runs backwards",
    "a person runs quickly", "someone jogs slowly", "a person dashes forward",
]


def leap_ratio(motion) -> float:
    """The worst joint's largest planted step over its largest decoded step."""
    J = np.asarray(motion.joints, np.float64)
    D = np.asarray(motion.network_joints, np.float64)
    planted = np.linalg.norm(np.diff(J, axis=0), axis=-1).max(0)
    decoded = np.linalg.norm(np.diff(D, axis=0), axis=-1).max(0)
    return float((planted / np.maximum(decoded, 1e-3)).max())


def run(quick: bool = False) -> dict:
    from ..core.generation.generate import Generator, Request
    from .inputs import model_dir

    model, what = model_dir()
    gen = Generator(model)
    print(f"model: {what} ({model})")
    prompts = PROMPTS[::5] if quick else PROMPTS
    bodies, seeds = (BODIES[:2], (0,)) if quick else (BODIES, (0, 1))
    rows = []
    for prompt in prompts:
        for shape in bodies:
            for seed in seeds:
                m = gen.generate_batch([Request(prompt, shape_text=shape, seed=seed)])[0]
                if m.network_joints is None:
                    continue
                r = leap_ratio(m)
                rows.append({"prompt": prompt, "body": shape or "average", "seed": seed, "ratio": r})
                flag = "  over" if r > GOAL else ""
                print(f"{prompt!r} / {shape or 'average'} / seed {seed}: {r:.2f}{flag}", flush=True)
    ratios = np.array([r["ratio"] for r in rows])
    print(f"{len(rows)} motions: worst {ratios.max():.2f}, median {np.median(ratios):.2f}, "
          f"{int((ratios > GOAL).sum())} over {GOAL:g}")
    return {"plant_leaps": {"rows": rows, "worst": float(ratios.max()), "over": int((ratios > GOAL).sum()),
                            "goal": GOAL}}
