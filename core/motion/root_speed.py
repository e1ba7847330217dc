"""The root's horizontal speed of a joint track: what the gait measures (``eval/gait.py``) and the
typical pace of a plain gait (``generation/typical_pace.py``) read, and the stretch of a capture
that goes at its cruising speed (``steady_span``: a gait once under way, its start from standing
and its stop left out), which the typical pace and the part judge's references read."""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError

CRUISING = 0.8               # a steady stretch keeps the root at >= this share of its cruising speed
STEADY_MIN_FRAMES = 20       # ... for at least this many frames (1 s at 20 fps)
STEADY_MAX_SHARE = 0.8       # ... and leaves out at least a fifth of the clip (else the clip is steady)


def _joints(joints) -> np.ndarray:
    j = np.asarray(joints, dtype=np.float64)
    if j.ndim != 3 or j.shape[1] < 22 or j.shape[2] != 3 or len(j) < 2 or not np.isfinite(j).all():
        raise ShapeMoveError(f"gait measures need finite (frames >= 2, 22, 3) joints, got shape {j.shape}")
    return j


def root_velocity(joints, fps: float = FPS) -> np.ndarray:
    """(T-1,2) horizontal (x, z) root velocity, m/s."""
    return np.diff(_joints(joints)[:, 0, [0, 2]], axis=0) * fps


def mean_speed(joints, fps: float = FPS) -> float:
    """Mean horizontal root speed (m/s): path length / duration."""
    return float(np.linalg.norm(root_velocity(joints, fps), axis=-1).mean())


def steady_span(joints, fps: float = FPS) -> tuple[int, int] | None:
    """(start, end) frames of the longest stretch whose root moves at >= ``CRUISING`` of its
    cruising speed (the 90th percentile of its horizontal speed, smoothed over 5 frames), when it
    lasts >= ``STEADY_MIN_FRAMES`` and leaves out >= 1 - ``STEADY_MAX_SHARE`` of the clip; else
    None (a clip steady throughout, or never for long)."""
    speed = np.linalg.norm(root_velocity(joints, fps), axis=-1)
    speed = np.convolve(speed, np.ones(5) / 5, "same")
    fast = np.concatenate([[False], speed >= CRUISING * np.quantile(speed, 0.9), [False]])
    edges = np.flatnonzero(np.diff(fast.astype(np.int8)))
    starts, ends = edges[::2], edges[1::2]
    if not len(starts):
        return None
    i = int(np.argmax(ends - starts))
    a, b = int(starts[i]), min(int(ends[i]) + 1, len(speed) + 1)   # speed[t] joins frames t and t + 1
    if b - a < STEADY_MIN_FRAMES or b - a > STEADY_MAX_SHARE * (len(speed) + 1):
        return None
    return a, b
