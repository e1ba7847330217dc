"""Foot contacts of a motion: per frame, which of the heels (ankle joints 7, 8) and toes (foot
joints 10, 11) rest on the floor. Detected from joint heights and speeds with hysteresis.

Contacts are (T,4) uint8 in the order ``CONTACT_IDS`` = [7, 8, 10, 11] (left ankle, right
ankle, left foot, right foot), the order stored per clip in ``contacts/ID.npy``. The HumanML3D
feature channels hold them in ``FEATURE_ORDER`` ([7, 10, 8, 11]): ``to_feature_order``.

Heights are taken relative to the motion's own floor level for each joint type (the height of the
ankle / ball joint when it stands on the floor differs between skeletons): a low percentile of
that joint type's height over the clip, both feet pooled. A joint enters contact when it is
within ``ENTER_HEIGHT`` of that level and slower than ``ENTER_SPEED``; it stays in contact
while within ``EXIT_HEIGHT`` and slower than ``EXIT_SPEED``. Runs shorter than ``MIN_RUN``
frames are dropped.
"""
from __future__ import annotations

import numpy as np

from ..body.skeleton import FOOT_JOINTS
from ..constants import FPS
from ..errors import ShapeMoveError

CONTACT_IDS = FOOT_JOINTS
FEATURE_ORDER = [0, 2, 1, 3]     # contacts[:, FEATURE_ORDER] -> feature channels (7, 10, 8, 11)
ENTER_HEIGHT = 0.04              # m above the joint type's floor level
EXIT_HEIGHT = 0.06
ENTER_SPEED = 0.35               # m/s
EXIT_SPEED = 0.7
MIN_RUN = 2                      # frames
FLOOR_PERCENTILE = 2.0


def floor_levels(joints) -> np.ndarray:
    """(2,) height of the ankle and of the ball joint standing on the floor: a low percentile of
    each joint type's height over the clip (both feet pooled)."""
    j = np.asarray(joints, dtype=np.float64)
    return np.array([np.percentile(j[:, [7, 8], 1], FLOOR_PERCENTILE),
                     np.percentile(j[:, [10, 11], 1], FLOOR_PERCENTILE)])


def joint_speeds(joints, fps: float) -> np.ndarray:
    """(T,4) speed (m/s) of the contact joints: central differences, one-sided at the ends."""
    p = np.asarray(joints, dtype=np.float64)[:, CONTACT_IDS]
    if len(p) < 2:
        return np.zeros(p.shape[:2])
    v = np.gradient(p, axis=0) * fps
    return np.linalg.norm(v, axis=-1)


def _hysteresis(enter: np.ndarray, stay: np.ndarray) -> np.ndarray:
    """Per column: on where ``enter``, kept on while ``stay``; a run that ``stay`` holds but never
    ``enter``s stays off. Done both ways in time, so a run is also entered from its end."""
    out = np.zeros_like(enter)
    for k in range(enter.shape[1]):
        on = False
        for t in range(enter.shape[0]):
            on = bool(enter[t, k]) or (on and bool(stay[t, k]))
            out[t, k] = on
        on = False
        for t in range(enter.shape[0] - 1, -1, -1):
            on = bool(enter[t, k]) or (on and bool(stay[t, k]))
            out[t, k] |= on
    return out


def _drop_short(c: np.ndarray, min_run: int) -> np.ndarray:
    out = c.copy()
    for k in range(c.shape[1]):
        t = 0
        while t < len(c):
            if c[t, k]:
                e = t
                while e < len(c) and c[e, k]:
                    e += 1
                if e - t < min_run:
                    out[t:e, k] = False
                t = e
            else:
                t += 1
    return out


def slow_enough(joints, fps: float = FPS) -> np.ndarray:
    """(T,>=22,3) joints -> (T,4) bool: where each contact joint moves along the floor as slowly as a
    joint resting on it, by the detector's speed thresholds (below ``ENTER_SPEED`` to enter,
    ``EXIT_SPEED`` to stay) on its horizontal speed (a heel rising at toe-off is left to the height
    rules: it rolls over its ball)."""
    flat = np.array(joints, dtype=np.float64)
    flat[..., 1] = 0.0
    v = joint_speeds(flat, fps)
    return _hysteresis(v < ENTER_SPEED, v < EXIT_SPEED)


def detect_contacts(joints, fps: float = FPS) -> np.ndarray:
    """(T,>=22,3) joints (metres, Y up) -> (T,4) uint8 contacts of joints 7, 8, 10, 11."""
    j = np.asarray(joints, dtype=np.float64)
    if j.ndim != 3 or j.shape[1] < 22 or j.shape[2] != 3 or not np.isfinite(j).all():
        raise ShapeMoveError(f"contacts need finite (frames, 22, 3) joints, got shape {j.shape}")
    levels = floor_levels(j)
    h = j[:, CONTACT_IDS, 1] - np.repeat(levels, 2)[None]
    v = joint_speeds(j, fps)
    c = _hysteresis((h < ENTER_HEIGHT) & (v < ENTER_SPEED), (h < EXIT_HEIGHT) & (v < EXIT_SPEED))
    return _drop_short(c, MIN_RUN).astype(np.uint8)


def to_feature_order(contacts) -> np.ndarray:
    """(..., 4) contacts of [7, 8, 10, 11] -> the feature channels' order [7, 10, 8, 11]."""
    return np.asarray(contacts)[..., FEATURE_ORDER]


def runs(column) -> list[tuple[int, int]]:
    """[(start, end)) of the runs of non-zero values of a (T,) array."""
    c = np.asarray(column).astype(bool)
    edges = np.flatnonzero(np.diff(np.r_[0, c.astype(np.int8), 0]))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))
