"""The typical pace of a gait: a prompt that names a gait and no pace ("a person walks forward",
"a man runs") gets the pace the training data's captures of that gait go at.

The T5's samples of a plain walk spread from 0.6 to 1.5 m/s (the default model's 10 candidates
for "a person walks forward") and the TMA that chooses among them hardly tells a brisk walk from a
slow one, so the choice fell anywhere in that spread: "a person runs forward" ran at a median
3.49 m/s over seeds 0-4 on the average body against 2.87 m/s for the captured runs (1.22x); now
2.67 m/s (0.93x; the candidates are judged by their decoded speed on the [BETA] head's body, a few
per cent above the planted motion's on the average body), walks 1.15 m/s against 1.19 (0.97x). So when a prompt names one gait of
``TYPICAL_SPEED`` and no pace word (``pace_words``), only the share ``NEAR_SHARE`` of the
candidates nearest that gait's typical speed (by ratio) compete (``rerank.CandidatePicker``).

``TYPICAL_SPEED``: per gait, the median root speed (m/s) of the built dataset's normal-style
captures of it on the average body (``norm_joints``), from ``python tools/typical_pace.py --data
data/built``. Speeds are the features' root speed along the path (``pace_words.gait_speed``), the
same number as the pelvis's path over the motion's length.
"""
from __future__ import annotations

import numpy as np

from ..data.actions import action_spans
from .pace_words import names_pace
from .part_prompts import LEGS

TYPICAL_SPEED = {"run": 2.87, "walk": 1.19}   # m/s; python tools/typical_pace.py --data data/built
NEAR_SHARE = 1 / 5   # the candidates nearest the typical pace that compete


def typical_speed(prompt: str) -> float | None:
    """The typical speed (m/s) of the one gait ``prompt`` names when it names no pace; else None."""
    gaits = {sp[2] for sp in action_spans(prompt) if sp[2] in LEGS}
    if len(gaits) != 1 or names_pace(prompt):
        return None
    return TYPICAL_SPEED.get(next(iter(gaits)))


def nearest_pace(speeds, among: np.ndarray, typical: float) -> np.ndarray:
    """(N,) bool: the share ``NEAR_SHARE`` of the candidates ``among`` (bool) whose ``speeds`` are
    nearest ``typical`` by ratio (at least one); ``among`` itself when it holds none."""
    among = np.asarray(among, bool)
    if not among.any():
        return among
    off = np.abs(np.log(np.maximum(np.asarray(speeds, np.float64), 1e-3) / typical))
    n = max(1, int(np.ceil(among.sum() * NEAR_SHARE)))
    cut = np.sort(off[among])[n - 1]
    return among & (off <= cut)
