"""The typical pace of each gait in the training data, the table the generator retimes plain gait
prompts toward (``core/generation/typical_pace.py``), written into a model folder:

    python tools/typical_pace.py --data data/built --model weights/default

Per gait (walk, jog, run): the median root speed (``eval.gait.mean_speed``: the pelvis's
horizontal path over its duration) once under way (over the capture's steady stretch,
``motion.root_speed.steady_span``, when it has one: HDM05's jogs are 4 steps from standing, at
1.56 m/s over the whole take and 1.84 once going) of the training split's captures of it on the average
body (``norm_joints``: betas 0, the body a prompt without shape words gets; strides scaled by the
pelvis height) that go straight (``typical_pace.straight``: the smoothed root's start-to-end
distance at least 0.9 of its path; a turning or circling capture is a different task), in their performer's plain way:
the clips labelled ``style: normal`` (the Bandai captures: one actor's plain way of doing it among
the styled ones: active, tired, proud, ...) or, for a gait with fewer than ``--least`` of those
(jog), its clips with no style label. Augmented copies are left out. Writes ``typical_pace.json``
into the model folder (atomically) and lists it in the folder's manifest; prints the table.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

GAITS = ("walk", "jog", "run")


def gait_speeds(data: Path, split: str = "train") -> dict[str, dict[str, list[float]]]:
    """{gait: {"normal" | "unstyled": speeds (m/s) of its straight captures of ``split``}}."""
    from shapemove.core.data.built_meta import is_real, iter_meta
    from shapemove.core.eval.gait import mean_speed
    from shapemove.core.motion.root_speed import steady_span
    from shapemove.core.generation.track import root_centre
    from shapemove.core.generation.typical_pace import straight

    ids = set((Path(data) / f"{split}.txt").read_text().split())
    out: dict[str, dict[str, list[float]]] = {}
    for meta in iter_meta(data):
        labels, cid = meta.get("labels") or {}, meta.get("id")
        actions = labels.get("actions") or []
        style = labels.get("style")
        if cid not in ids or not is_real(meta) or not actions or actions[0] not in GAITS:   # each capture once
            continue
        if style not in ("normal", None):
            continue
        path = Path(data) / "norm_joints" / f"{cid}.npy"
        if not path.is_file():
            continue
        joints = np.load(path)
        if not straight(root_centre(joints)):
            continue
        span = steady_span(joints) or (0, len(joints))
        out.setdefault(actions[0], {}).setdefault("normal" if style else "unstyled", []).append(
            mean_speed(joints[span[0]:span[1]], float(meta.get("fps", 20))))
    return out


def table(found: dict, least: int) -> dict:
    """The ``typical_pace.json`` content: per gait its speed, the clips and which captures."""
    from shapemove.core.generation.typical_pace import FORMAT, STRAIGHT

    gaits = {}
    for gait in GAITS:
        kinds = found.get(gait, {})
        kind = "normal" if len(kinds.get("normal", [])) >= least else "unstyled"
        speeds = kinds.get(kind, [])
        if len(speeds) >= least:
            q = np.percentile(speeds, [25, 50, 75])
            gaits[gait] = {"speed": round(float(q[1]), 3), "clips": len(speeds), "captures": kind,
                           "quartiles": [round(float(q[0]), 3), round(float(q[2]), 3)]}
    return {"format": FORMAT, "gaits": gaits,
            "made_by": "python tools/typical_pace.py --data DATA --model MODEL (training split, average body, "
                       f"straight captures: start-to-end >= {STRAIGHT:g} of the path; over each one's steady stretch)"}


def main(argv=None) -> int:
    from shapemove.core.atomic import atomic_write_json
    from shapemove.core.generation.typical_pace import TABLE
    from shapemove.core.model_files import add_to_manifest

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=Path("data/built"), help="a built dataset (data build)")
    ap.add_argument("--model", type=Path, default=None, help="model folder to write typical_pace.json into")
    ap.add_argument("--least", type=int, default=5, help="captures a gait needs to be listed")
    args = ap.parse_args(argv)
    found = table(gait_speeds(args.data), args.least)
    if not found["gaits"]:
        print(f"no straight plain gait captures in {args.data}")
        return 1
    for gait, row in found["gaits"].items():
        print(f"{gait}: {row['speed']:.2f} m/s median over {row['clips']} {row['captures']} captures "
              f"(quartiles {row['quartiles'][0]:.2f}-{row['quartiles'][1]:.2f})")
    if args.model is not None:
        path = atomic_write_json(args.model / TABLE, found)
        if (args.model / "manifest.json").is_file():
            add_to_manifest(args.model, [path])
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
