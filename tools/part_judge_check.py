"""How the part judge's legs read real clips it was not built from, four ways, in one run:

    python tools/part_judge_check.py --data data/built --model weights/default [--json out/judge_check.json]

- **test clips**: the real test split (``part_judge_accuracy.real_accuracy``);
- **without their take**: each reference among the others (``leave_one_out``);
- **steady stretches**: the part of each real locomotion clip at its cruising speed, as a looped
  take plays it (``steady_accuracy``);
- **other bodies, straight**: up to ``--per-class`` built-in library takes of each gait, posed by
  their own rotations on ``--bodies`` bodies (betas drawn from N(0, 1), clipped at 2.5, seeded),
  played straight (``part_judge.straight_joints``), whole and their steady stretch, each without
  its take: a gait on the body a prompt asks for, off its captured path.

No generated motion is read: the figures say what the judge does with real performances, so a
change to it is not chosen by what it makes of the product's motions.
"""
from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))


def other_bodies(judge, model: Path, bodies: int, per_class: int, seed: int = 0) -> dict:
    """{"<gait>/<whole|steady>": [n, right]} over library takes on other bodies, played straight."""
    from shapemove.core.body.openbody import OpenBody
    from shapemove.core.data.compose_parts import LEGS_ACTIONS
    from shapemove.core.data.motion_library import MotionLibrary
    from shapemove.core.eval.part_judge import CIRCLE, steady_span, straight_joints
    from shapemove.core.generation.captured_takes import TakePool
    from shapemove.core.generation.retarget import shaped_take
    from shapemove.core.models.motion_memory import take_of

    body = OpenBody.load()
    pool = TakePool(body, MotionLibrary.load(model / "library.npz"))
    rng = np.random.default_rng(seed)
    shapes = [rng.normal(0.0, 1.0, 10).clip(-2.5, 2.5) for _ in range(bodies)]
    by: dict[str, list[int]] = defaultdict(list)
    for i, action in enumerate(pool.actions):
        if action in LEGS_ACTIONS:
            by["walk" if action == CIRCLE else action].append(i)
    knn = judge.legs
    takes = np.asarray([take_of(str(s)) for s in knn.sources])
    out: dict[str, list[int]] = defaultdict(lambda: [0, 0])
    for gait, idx in sorted(by.items()):
        for i in sorted(rng.choice(idx, min(per_class, len(idx)), replace=False)):
            away = sorted(set(knn.sources[takes == take_of(pool.ids[i])]))
            for betas in shapes:
                j = straight_joints(np.asarray(shaped_take(pool.take(int(i)), body, betas), np.float64)[:, :22])
                span = steady_span(j)
                for kind, jj in [("whole", j)] + ([("steady", j[span[0]:span[1]])] if span else []):
                    out[f"{gait}/{kind}"][0] += 1
                    out[f"{gait}/{kind}"][1] += knn.classify(jj, away) == gait
    return dict(sorted(out.items()))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, required=True, help="the built dataset (its real clips)")
    ap.add_argument("--model", type=Path, default=Path("weights/default"), help="model folder with the built-in library")
    ap.add_argument("--bodies", type=int, default=3)
    ap.add_argument("--per-class", type=int, default=25)
    ap.add_argument("--json", type=Path, help="write the figures here too")
    args = ap.parse_args(argv)

    from shapemove.core.eval.part_judge import PartJudge
    from shapemove.core.eval.part_judge_accuracy import leave_one_out, real_accuracy, steady_accuracy

    judge = PartJudge.from_data(args.data)
    res = {"references": judge.info["legs_references"],
           "test_clips": real_accuracy(judge, args.data, "test")["legs"],
           "without_their_take": leave_one_out(judge)["legs"],
           "steady_stretches": steady_accuracy(judge, args.data),
           "other_bodies_straight": other_bodies(judge, args.model, args.bodies, args.per_class)}
    share = lambda t: f"{t['accuracy']:.1%} of {t['n']}"  # noqa: E731
    print("legs references (clips):", res["references"])
    print("real test clips:", share(res["test_clips"]), {c: f"{v['accuracy']:.0%} of {v['n']}" for c, v in res["test_clips"]["per_class"].items()})
    print("references without their take:", share(res["without_their_take"]),
          {c: f"{v['accuracy']:.0%} of {v['n']}" for c, v in res["without_their_take"]["per_class"].items()})
    print("steady stretches without their take:", share(res["steady_stretches"]),
          {c: f"{v['accuracy']:.0%} of {v['n']}" for c, v in res["steady_stretches"]["per_class"].items()})
    ob = res["other_bodies_straight"]
    print(f"library takes on {args.bodies} other bodies, straight, without their take:",
          f"{sum(r for _, r in ob.values())} of {sum(n for n, _ in ob.values())}", {k: f"{r}/{n}" for k, (n, r) in ob.items()})
    if args.json:
        from shapemove.core.atomic import atomic_write_json

        atomic_write_json(args.json, res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
