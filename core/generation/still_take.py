"""A captured take that holds still is no performance of an action that moves.

Some captures are labelled with an action they only pose: CMU 49_15, "static dance pose - folded
in, head lowered, leg bent", is a take of "dance" in which nothing moves for 7.9 s. Offered for "a
woman dances in place", it won the choice (nothing travels, as "in place" asks) and the user got a
statue. A take is still when, over its busiest second, no joint moves faster on average than
``STILL_SPEED`` relative to the pelvis, nor the pelvis over the floor (that take: 0.055 m/s; the
stillest of the library's other takes, a sad wave goodbye: 0.14 m/s). It competes only where the
words ask for a pose (``HOLDS_STILL``) or to stand still ("waits"); like a slow take (``typical_pace.slow_take``), it does not
compete elsewhere, and the T5's samples and the other takes do.
"""
from __future__ import annotations

import numpy as np

from ..constants import FPS

STILL_SPEED = 0.1        # m/s: the liveliest joint's mean speed over the busiest second, below it a take is still
HOLDS_STILL = ("pose",)  # the actions a still take performs


def liveliest_speed(joints, fps: float = FPS) -> float:
    """m/s: over the busiest second of (T, J, 3) ``joints`` (Y up), the mean speed of the joint that
    moves most relative to the pelvis (joint 0), the pelvis counted by its path over the floor; the
    whole motion when it is shorter than a second; 0 for a single frame."""
    j = np.asarray(joints, np.float64)
    if len(j) < 2:
        return 0.0
    rel = j - j[:, :1]
    rel[:, 0] = j[:, 0] * (1.0, 0.0, 1.0)
    speed = np.linalg.norm(np.diff(rel, axis=0), axis=-1) * fps          # (T-1, J)
    w = int(min(max(1, round(fps)), len(speed)))
    c = np.concatenate([np.zeros((1, speed.shape[1])), np.cumsum(speed, 0)])
    return float(((c[w:] - c[:-w]) / w).max())


def still_take(window, asked: str | None, words=None) -> bool:
    """Whether the captured take ``window`` (``captured_takes.Window``) holds still (module docstring)
    where the words (``plan.words.Words``) ask neither a pose nor to stand still ("waits")."""
    from ..motion.features import joints_from_features

    if asked in HOLDS_STILL or (words is not None and words.stand_still):
        return False
    f = np.asarray(window.features, np.float32)
    return len(f) > 0 and liveliest_speed(joints_from_features(f)) < STILL_SPEED
