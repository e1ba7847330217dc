"""How often the part judge (``part_judge.py``) is right on real captured clips it was not built from.

    res = real_accuracy(judge, "data/built", "test")
    res["legs"]["accuracy"], res["arms"]["accuracy"], res["side"]["accuracy"], res["path"]

- ``legs``: the gait of each real clip of ``split`` whose labels give one (``part_judge.legs_label``:
  a locomotion of ``LEGS_ACTIONS`` or a standing gesture, "stand"); ``path``: circle or straight
  for the locomotion clips (``path_label``);
- ``arms``: the gesture of each standing gesture clip, ``NO_GESTURE`` for the locomotion clips;
- ``side``: the clips whose source label names a side (``named_side``: Bandai's
  raise-up-left-hand / wave-right-hand ..., HDM05's kickLFront, grabHighR, depositFloorR) and the
  mirror image of each (``data/mirror.py``, the other side), judged by ``side_of`` on the named part.

Each as {"accuracy", "n", "per_class": {label: {"n", "accuracy"}}, "confusion": {label: {pred: n}}}.
``leave_one_out(judge)`` is the same on the judge's own references, each without its own take;
``steady_accuracy(judge, data)`` on the steady stretches of real locomotion clips
(``motion.root_speed.steady_span``), each without its own take: a gait as a looped take plays it.
"""
from __future__ import annotations

import re

import numpy as np

from ..data.mirror import mirror_joints
from .part_judge import actions_of, arms_label, best, legs_label, load_joints, path_label, path_of, real_clips, side_of

_BANDAI_SIDE = re.compile(r"(left|right)-hand")
_HDM05_SIDE = {re.compile(r"^kick(L|R)"): "foot", re.compile(r"^(?:grabHigh|depositFloor)(L|R)"): "hand"}


def named_side(meta: dict) -> tuple[str, str] | None:
    """(side, part) named by a real clip's source label ("left", "hand"), or None."""
    labels = meta.get("labels") if isinstance(meta.get("labels"), dict) else {}
    if meta.get("dataset") == "bandai":
        m = _BANDAI_SIDE.search(str(labels.get("content", "")))
        return (m.group(1), "hand") if m else None
    if meta.get("dataset") == "hdm05":
        cls = str(labels.get("class", ""))
        for rx, part in _HDM05_SIDE.items():
            m = rx.match(cls)
            if m:
                return ("left" if m.group(1) == "L" else "right", part)
    return None


def tally(pairs: list[tuple[str, str]]) -> dict:
    """[(truth, prediction)] -> accuracy overall, per class and the confusion counts."""
    per: dict = {}
    conf: dict = {}
    for t, p in pairs:
        d = per.setdefault(t, [0, 0])
        d[0] += 1
        d[1] += t == p
        conf.setdefault(t, {}).setdefault(p, 0)
        conf[t][p] += 1
    n = len(pairs)
    return {"accuracy": sum(t == p for t, p in pairs) / n if n else None, "n": n,
            "per_class": {c: {"n": d[0], "accuracy": d[1] / d[0]} for c, d in sorted(per.items())},
            "confusion": {c: dict(sorted(v.items())) for c, v in sorted(conf.items())}}


def real_accuracy(judge, data, split: str = "test", max_clips: int | None = None, seed: int = 0,
                  progress: bool = True, metas: list[dict] | None = None) -> dict:
    """The judge on the real clips of ``split`` (module docstring); ``max_clips``: a seeded random
    subset of the labelled ones; ``metas``: those clips' metas instead of the split's."""
    from tqdm import tqdm

    metas = real_clips(data, split) if metas is None else metas
    metas = [m for m in metas if legs_label(actions_of(m)) is not None or named_side(m) is not None]
    if max_clips is not None and len(metas) > max_clips:
        keep = np.sort(np.random.default_rng(seed).choice(len(metas), max_clips, replace=False))
        metas = [metas[i] for i in keep]
    legs, arms, path, side = [], [], [], []
    for m in tqdm(metas, desc=f"part judge on real {split} clips", unit="clip", disable=not progress):
        j = load_joints(data, m["id"])
        if j is None:
            continue
        acts = actions_of(m)
        if (g := legs_label(acts)) is not None:
            legs.append((g, judge.legs.classify(j)))
        if (a := arms_label(acts)) is not None:
            arms.append((a, judge.arms.classify(j)))
        if (p := path_label(acts)) is not None:
            path.append((p, path_of(j)))
        if (named := named_side(m)) is not None:
            s, part = named
            side.append((s, side_of(j, part)))
            side.append(("right" if s == "left" else "left", side_of(mirror_joints(j), part)))
    return {"split": split, "legs": tally(legs), "arms": tally(arms), "path": tally(path), "side": tally(side),
            "references": dict(judge.info)}


def steady_accuracy(judge, data, splits: tuple[str, ...] = ("train", "test"), progress: bool = True) -> dict:
    """The legs judge on the steady stretch of each real locomotion clip of ``splits`` that has one
    (``steady_span``), each without its own take (its stretch is a reference too): ``tally``."""
    from tqdm import tqdm

    from ..models.motion_memory import take_of
    from ..motion.root_speed import steady_span
    from .part_judge import STAND

    knn = judge.legs
    takes = np.asarray([take_of(str(s)) for s in knn.sources])
    metas = [m for split in splits for m in real_clips(data, split) if legs_label(actions_of(m)) not in (None, STAND)]
    pairs = []
    for m in tqdm(metas, desc="part judge on steady stretches", unit="clip", disable=not progress):
        j = load_joints(data, m["id"])
        span = steady_span(j) if j is not None else None
        if span is None:
            continue
        away = sorted(set(knn.sources[takes == take_of(m["id"])]))
        pairs.append((legs_label(actions_of(m)), knn.classify(j[span[0]:span[1]], away)))
    return tally(pairs)


def leave_one_out(judge) -> dict:
    """Each reference clip classified among the others without its captured take
    (``motion_memory.take_of``: the clip, its mirror image, a source's own mirrored take such as
    DeepMimic's ``*_mirror``), as a copied memory clip is judged: how often a real performance of a
    class is read right when it is not one of the references. ``tally`` per part, each class also
    with its number of takes (a class of one take is never read right this way)."""
    from ..models.motion_memory import take_of

    out = {}
    for name, knn in (("legs", judge.legs), ("arms", judge.arms)):
        takes = np.asarray([take_of(str(s)) for s in knn.sources])
        pairs = []
        for i in np.flatnonzero(~knn.stretches)[::2]:  # the clip itself (its mirror follows it), not its steady stretch
            away = sorted(set(knn.sources[takes == takes[i]]))
            pairs.append((str(knn.labels[i]), best(knn.scores_of(knn.X[i], away))))
        out[name] = tally(pairs)
        for c, v in out[name]["per_class"].items():
            v["takes"] = len(set(takes[knn.labels == c]))
    return out

