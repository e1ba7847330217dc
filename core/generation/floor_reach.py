"""A pick-up or a put-down reaches the floor: the candidates whose hand goes down to it compete.

The TMA that chooses among the candidates (``rerank``) weighs who moves as much as what they do:
for "an old woman picks up a box" it chose a sample of an old woman standing about, her wrists
never lower than 0.85 m, over HDM05's captured put-downs played backwards (each credited as a take
of the asked action), whose right wrist goes down to 0.19-0.25 m. A hand that reaches the floor is
plain in the joints, so when the plan's action is one of ``vocabulary.TO_THE_FLOOR``, the
candidates whose lowest wrist comes under ``LOW_HAND`` of their head's highest are the ones that
compete (the put-downs: 0.12-0.15); when none does, all compete.

    keep = floor_reached("pick up", feats, keep)     # (N,) bool among (T, 263) candidates
"""
from __future__ import annotations

import numpy as np

from ..body.skeleton import JOINT_NAMES
from ..motion.features import height_column
from ..plan.vocabulary import TO_THE_FLOOR

LOW_HAND = 0.25   # a wrist this share of the head's highest above the floor reaches it
WRISTS_Y = [height_column(JOINT_NAMES.index(n)) for n in ("left_wrist", "right_wrist")]
HEAD_Y = height_column(JOINT_NAMES.index("head"))


def reaches_floor(features) -> bool:
    """Whether a (T, 263) candidate's hand goes down to the floor (module doc)."""
    f = np.asarray(features, dtype=np.float64)
    return bool(f[:, WRISTS_Y].min() < LOW_HAND * max(f[:, HEAD_Y].max(), 1e-6))


def floor_reached(action: str | None, feats: list, keep: np.ndarray) -> np.ndarray:
    """``keep`` narrowed to the candidates whose hand reaches the floor when ``action`` is one of
    ``TO_THE_FLOOR`` and any of them does (module doc)."""
    if action not in TO_THE_FLOOR:
        return keep
    reach = np.array([reaches_floor(f) for f in feats]) & keep
    return reach if reach.any() else keep
