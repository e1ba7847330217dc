"""How the action signatures (``action_signatures.py``) read real captured clips: per action, the
share of the built data's real clips of it that pass each signature.

Each real clip (not augmented, mirrored or composed: ``built_meta.is_real``) of the split whose
first labelled action is its action is read whole, or, with ``seconds``, as a window of that length
as the product plays it in a sequence's segment: a change of posture's last
(``plan/vocabulary.POSTURE_CHANGES``: a lie-down ends lying), any other's busiest (the most joint
motion). The signatures read no reference, so a clip is never judged against itself.

    table = signature_table("data/built", "train", seconds=3.0)   # {action: {signature: share, "n": clips}}
    own_share(table)                                              # {signature: share of its own clips}
"""
from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np

from ..constants import FPS
from .action_signatures import SIGNED, signatures, signed

MIN_FRAMES = 10


def busiest(joints: np.ndarray, frames: int) -> np.ndarray:
    """The window of ``frames`` frames of (T, J, 3) ``joints`` that move most (all of them when shorter)."""
    if len(joints) <= frames:
        return joints
    step = np.linalg.norm(np.diff(joints, axis=0), axis=2).sum(axis=1)
    c = np.concatenate([[0.0], np.cumsum(step)])
    s = int(np.argmax(c[frames - 1:] - c[:len(c) - frames + 1]))
    return joints[s:s + frames]


def signature_table(data, split: str = "train", seconds: float | None = None) -> dict:
    """{action (a form of a jump as "jump"): {signature: share of its real clips passing, "n": clips}}."""
    from ..data.built_meta import is_real, iter_meta
    from ..plan.vocabulary import POSTURE_CHANGES

    data = Path(data)
    passed: dict = defaultdict(lambda: defaultdict(int))
    counts: dict = defaultdict(int)
    for m in iter_meta(data):
        labels = m.get("labels") if isinstance(m.get("labels"), dict) else {}
        acts = labels.get("actions") or []
        if not is_real(m) or m.get("split") != split or not acts or labels.get("sequence"):
            continue
        f = data / "new_joints" / f"{m['id']}.npy"
        if not f.is_file():
            continue
        j = np.load(f, allow_pickle=False)
        if j.ndim != 3 or len(j) < MIN_FRAMES:
            continue
        if seconds:
            w = int(round(seconds * FPS))
            j = j[-w:] if acts[0] in POSTURE_CHANGES else busiest(j, w)
        a = signed(acts[0]) or acts[0]
        counts[a] += 1
        for k, ok in signatures(j).items():
            passed[a][k] += bool(ok)
    return {a: {**{k: passed[a][k] / counts[a] for k in SIGNED}, "n": counts[a]} for a in sorted(counts)}


def own_share(table: dict) -> dict[str, float]:
    """{signature: the share of its own action's real clips that pass it} (signatures with clips)."""
    return {k: table[k][k] for k in SIGNED if k in table}


def false_share(table: dict) -> dict[str, float]:
    """{signature: the share of every other action's real clips that pass it}."""
    out = {}
    for k in SIGNED:
        others = [a for a in table if a != k]
        n = sum(table[a]["n"] for a in others)
        out[k] = sum(table[a][k] * table[a]["n"] for a in others) / n if n else 0.0
    return out
