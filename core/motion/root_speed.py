"""The root's horizontal speed of a joint track: what the gait measures (``eval/gait.py``) and the
typical pace of a plain gait (``generation/typical_pace.py``) read."""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError


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
