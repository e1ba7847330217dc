"""Does planting add leaps? On the default model, 40 prompts (courses, squats, jumps, runs) x 3
bodies x 2 seeds: per motion, each joint's largest step in one frame of the planted motion over
the same joint's largest step in the decoded track it was planted from (``network_joints``: for a
captured take, the take posed on the body before planting); the worst joint's ratio, the worst
ratio of each joint over the bench, and the motions over the goal (<= 1.5 for every motion), for
generated and captured motions apart. Default settings (captured takes compete). Deterministic
(seeds 0 and 1)."""
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


def joint_ratios(motion) -> np.ndarray:
    """(22,) each joint's largest step in one frame of the planted motion over its largest step in
    the decoded track (a decoded step under a millimetre counted as one)."""
    from ..core.generation.seam_pace import steps

    planted, decoded = steps(motion.joints), steps(motion.network_joints)
    return planted.max(0) / np.maximum(decoded.max(0), 1e-3)


def leap_ratio(motion) -> float:
    """The worst joint's largest planted step over its largest decoded step."""
    return float(joint_ratios(motion).max())


def run(quick: bool = False) -> dict:
    from ..core.body.skeleton import JOINT_NAMES
    from ..core.generation.generate import Generator, Request
    from ..core.generation.seam_pace import steps
    from .inputs import model_dir

    model, what = model_dir()
    gen = Generator(model)
    print(f"model: {what} ({model})")
    prompts = PROMPTS[::5] if quick else PROMPTS
    bodies, seeds = (BODIES[:2], (0,)) if quick else (BODIES, (0, 1))
    rows, per_joint = [], []
    for prompt in prompts:
        for shape in bodies:
            for seed in seeds:
                m = gen.generate_batch([Request(prompt, shape_text=shape, seed=seed)])[0]
                if m.network_joints is None:
                    continue
                r = joint_ratios(m)
                j = int(r.argmax())
                step = float(steps(m.joints)[:, j].max())
                source = "captured" if (m.provenance or "").startswith("captured") else "generated"
                rows.append({"prompt": prompt, "body": shape or "average", "seed": seed, "ratio": float(r.max()),
                             "joint": JOINT_NAMES[j], "step_m": step, "source": source})
                per_joint.append(r)
                flag = "  over" if r.max() > GOAL else ""
                print(f"{prompt!r} / {shape or 'average'} / seed {seed} ({source}): {r.max():.2f} "
                      f"({JOINT_NAMES[j]}, {step:.3f} m){flag}", flush=True)
    ratios = np.array([r["ratio"] for r in rows])
    worst = np.max(per_joint, axis=0)
    print(f"{len(rows)} motions: worst {ratios.max():.2f}, median {np.median(ratios):.2f}, "
          f"{int((ratios > GOAL).sum())} over {GOAL:g}")
    for source in ("generated", "captured"):
        got = [r["ratio"] for r in rows if r["source"] == source]
        if got:
            print(f"  {source}: {len(got)} motions, worst {max(got):.2f}, {sum(x > GOAL for x in got)} over")
    print("worst ratio per joint: " + ", ".join(f"{n} {w:.2f}" for n, w in zip(JOINT_NAMES, worst)))
    over = [r for r in rows if r["ratio"] > GOAL]
    for r in sorted(over, key=lambda r: -r["ratio"]):
        print(f"  over: {r['prompt']!r} / {r['body']} / seed {r['seed']}: {r['ratio']:.2f} ({r['joint']}, "
              f"{r['step_m']:.3f} m in a frame)")
    return {"plant_leaps": {"rows": rows, "worst": float(ratios.max()), "over": len(over), "goal": GOAL,
                            "worst_per_joint": {n: float(w) for n, w in zip(JOINT_NAMES, worst)}}}
