"""Do pace words change the pace? Each row of a pace set (``configs/tuning_pace.json``; its blind
twin ``configs/heldout_pace_blind.json``) asks one gait slow, plain and fast; every prompt is
generated on several seeds and the chosen motion's root speed is measured on the final joints
(``gait.mean_speed``: the pelvis's horizontal path over the motion's length, the same number a
user would read off the rig, not the features the generator chose by).

    python tools/pace_check.py --model weights/default [--seeds 4] [--json out/pace.json] [--data data/built]

Prints each row's mean speeds (slow / plain / fast, m/s), whether they are in order, and over all
rows the speed ratios slow/plain and fast/plain. With ``--data`` (the built dataset), each motion
is also judged as ``eval paraphrase`` judges (what the rig plays, ``motion_features``: the TMA's and
the raw features' 5 nearest training clips, a retrieved clip judged without its take): a pace must
not cost the gait, so the share of motions still read as the row's gait (the plain prompt's, by the
action patterns) is printed.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np


def _judges(gen, data) -> dict:
    """The two judges of ``eval paraphrase``: 5 nearest training clips by TMA embedding and by raw features."""
    from shapemove.core.eval.action_classifier import ActionClassifier
    from shapemove.core.generation.model_bundle import model_files
    from shapemove.core.eval.tma_embed import load_tma

    tma = load_tma(model_files(gen.model_dir)["tma"])
    return {"TMA": ActionClassifier.from_data(tma, data, gen.known_actions, progress=False),
            "raw-feature": ActionClassifier.from_features(data, gen.known_actions, progress=False)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", type=Path, default=None)
    ap.add_argument("--prompts", type=Path, default=Path(__file__).resolve().parents[1] / "configs" / "tuning_pace.json")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--seconds", type=float, default=4.0)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--data", type=Path, default=None, help="built dataset: also judge each motion's action")
    args = ap.parse_args(argv)
    from shapemove.core.data.actions import action_spans
    from shapemove.core.eval.gait import mean_speed
    from shapemove.core.motion.features import motion_features
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.plan.part_prompts import LEGS

    gen = Generator(args.model)
    judges = _judges(gen, args.data) if args.data else {}
    rows = json.loads(args.prompts.read_text())["rows"]
    out, ordered, ratios = [], 0, {"slow": [], "fast": []}
    kept = {name: [0, 0] for name in judges}   # motions read as the row's gait, motions judged
    for row in rows:
        gait = next((sp[2] for sp in action_spans(row[1]) if sp[2] in LEGS), None)
        speeds, reads = [], {name: [] for name in judges}
        for prompt in row:
            made = gen.generate_batch([Request(prompt, seconds=args.seconds, seed=s) for s in range(args.seeds)])
            speeds.append(float(np.mean([mean_speed(m.joints, m.fps) for m in made])))
            for name, judge in judges.items():
                got = judge.classify([motion_features(m) for m in made], exclude=[list(m.retrieved_clips) for m in made])
                reads[name].append(got)
                kept[name][0] += sum(a == gait for a in got)
                kept[name][1] += len(got)
        ok = speeds[0] < speeds[1] < speeds[2]
        ordered += ok
        ratios["slow"].append(speeds[0] / speeds[1])
        ratios["fast"].append(speeds[2] / speeds[1])
        out.append({"prompts": row, "gait": gait, "speeds": speeds, "in_order": ok, "read_as": reads})
        print(f"{'ok' if ok else '--'}  {speeds[0]:.2f} / {speeds[1]:.2f} / {speeds[2]:.2f} m/s  {row[1]}", flush=True)
    summary = {"rows": len(rows), "in_order": ordered, "seeds": args.seeds,
               "slow_over_plain": float(np.median(ratios["slow"])), "fast_over_plain": float(np.median(ratios["fast"])),
               "read_as_the_gait": {name: k[0] / max(1, k[1]) for name, k in kept.items()}}
    print(f"in order (slow < plain < fast): {ordered} of {len(rows)}; median speed ratio slow/plain "
          f"{summary['slow_over_plain']:.2f}, fast/plain {summary['fast_over_plain']:.2f}")
    for name, (right, n) in kept.items():
        print(f"read as the row's gait by the {name} judge: {right} of {n} motions ({100 * right / max(1, n):.1f} %)")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"summary": summary, "rows": out}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
