"""The typical pace of each gait in the training data: the median root speed of the normal-style
captures of that gait on the average body, the numbers behind ``core/generation/typical_pace.py``.

    python tools/typical_pace.py --data data/built

A clip counts when its meta labels it ``style: normal`` (the Bandai captures: one actor's plain
way of doing it among the styled ones: active, tired, proud, ...) and its first action is a gait
of ``part_prompts.LEGS``; augmented copies (``augmented_from``) are left out, since the average-body
copy is the same. Its speed is ``eval.gait.mean_speed`` (the pelvis's horizontal path over the
clip's length) of ``norm_joints``: the capture on the average body (betas 0, the body a prompt
without shape words gets), strides scaled by the pelvis height. Prints, per gait, the clips, the
median and the spread, then the ``TYPICAL_SPEED`` line to paste into that module.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))


def typical_speeds(data: Path, least: int = 3) -> dict[str, list[float]]:
    """{gait: the root speeds (m/s) of its normal-style captures on the average body}, for the gaits
    with at least ``least`` such clips."""
    from shapemove.core.data.built_meta import iter_meta
    from shapemove.core.eval.gait import mean_speed
    from shapemove.core.generation.part_prompts import LEGS

    speeds: dict[str, list[float]] = {}
    for meta in iter_meta(data):
        labels, cid = meta.get("labels") or {}, meta.get("id")
        actions = labels.get("actions") or []
        if meta.get("augmented_from") or labels.get("style") != "normal" or not actions or actions[0] not in LEGS:
            continue
        path = Path(data) / "norm_joints" / f"{cid}.npy"
        if path.is_file():
            speeds.setdefault(actions[0], []).append(mean_speed(np.load(path), float(meta.get("fps", 20))))
    return {g: s for g, s in sorted(speeds.items()) if len(s) >= least}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=Path("data/built"), help="a built dataset (data build)")
    ap.add_argument("--least", type=int, default=3, help="clips a gait needs to be listed")
    args = ap.parse_args(argv)
    found = typical_speeds(args.data, args.least)
    if not found:
        print(f"no normal-style gait captures in {args.data}")
        return 1
    for gait, s in found.items():
        q = np.percentile(s, [25, 50, 75])
        print(f"{gait}: {len(s)} clips, median {q[1]:.2f} m/s (quartiles {q[0]:.2f}-{q[2]:.2f})")
    line = ", ".join(f'"{g}": {np.median(s):.2f}' for g, s in found.items())
    print(f"TYPICAL_SPEED = {{{line}}}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
