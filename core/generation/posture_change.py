"""A change of posture the words ask for is made: "gets up" rises from low, "lies down" and "sits
down" end low.

The TMA that chooses among the candidates (``rerank``) reads the words that say who moves and how
as readily as the action: for "an old man gets up" it scored a sample of an old man standing
still 0.74 and DeepMimic's captured get-ups from the floor 0.24 and 0.15 (each credited 0.3 as a
take of the asked action), so the man stood for 3 s. A change of posture is plain in the root's
height, so when the plan's action is one (``plan/vocabulary.POSTURE_CHANGES``, with the way the
root goes), the candidates that make it are the ones that compete: the root's height at the end
against the start, as a share of the candidate's highest root, moves by at least ``MIN_CHANGE``
the way the action goes (the built data's get-ups and lie-downs move 0.7 of it; its walks at most
0.2). When no candidate makes it, all compete.

    keep = posture_kept("get up", feats, keep)     # (N,) bool among (T, 263) candidates
"""
from __future__ import annotations

import numpy as np

from ..plan.vocabulary import POSTURE_CHANGES

MIN_CHANGE = 0.3   # of the candidate's highest root
ENDS = 5           # frames averaged at the start and at the end


def posture_change(features) -> float:
    """The root's height at the end minus at the start of a (T, 263) candidate, as a share of its
    highest root."""
    y = np.asarray(features, dtype=np.float64)[:, 3]
    return float((y[-ENDS:].mean() - y[:ENDS].mean()) / max(y.max(), 1e-6))


def posture_kept(action: str | None, feats: list, keep: np.ndarray) -> np.ndarray:
    """``keep`` narrowed to the candidates that make ``action``'s change of posture, when it is one
    and any of them makes it."""
    way = POSTURE_CHANGES.get(action or "")
    if way is None:
        return keep
    makes = np.array([way * posture_change(f) >= MIN_CHANGE for f in feats]) & keep
    return makes if makes.any() else keep
