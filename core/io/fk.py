"""Forward kinematics of a mocap skeleton over all frames at once (numpy, float64).

Shared by the BVH and ASF/AMC readers. Frames are vectorised; the only Python loop runs over the
joints (tens), never over the frames (thousands).
"""
from __future__ import annotations

import numpy as np


def axis_rotation(axis: str, angles: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about ``axis`` ('x', 'y' or 'z') by ``angles`` radians (...)."""
    c, s = np.cos(angles), np.sin(angles)
    one, zero = np.ones_like(c), np.zeros_like(c)
    if axis == "x":
        rows = [one, zero, zero, zero, c, -s, zero, s, c]
    elif axis == "y":
        rows = [c, zero, s, zero, one, zero, -s, zero, c]
    elif axis == "z":
        rows = [c, -s, zero, s, c, zero, zero, zero, one]
    else:
        raise ValueError(f"unknown rotation axis {axis!r}")
    return np.stack(rows, axis=-1).reshape(*np.shape(angles), 3, 3)


def euler_matrix(axes: str, angles: np.ndarray) -> np.ndarray:
    """Intrinsic Euler rotation: ``axes`` like 'zxy', angles (..., len(axes)) radians.

    R = R_axes[0] @ R_axes[1] @ ... (the BVH convention: channels listed outermost first)."""
    angles = np.asarray(angles, dtype=np.float64)
    out = np.broadcast_to(np.eye(3), (*angles.shape[:-1], 3, 3)).copy()
    for k, ax in enumerate(axes):
        out = out @ axis_rotation(ax, angles[..., k])
    return out


def forward_kinematics(parents, translations: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """World joint positions.

    parents (J,) with parents[j] < j and -1 for roots; translations (T,J,3) of each joint in its
    parent's frame (the root's is its world position); rotations (T,J,3,3) local rotations.
    Returns (T,J,3).
    """
    T, J = translations.shape[:2]
    world_rot = np.empty((T, J, 3, 3))
    world_pos = np.empty((T, J, 3))
    for j in range(J):
        p = int(parents[j])
        if p < 0:
            world_rot[:, j] = rotations[:, j]
            world_pos[:, j] = translations[:, j]
        else:
            world_rot[:, j] = world_rot[:, p] @ rotations[:, j]
            world_pos[:, j] = world_pos[:, p] + (world_rot[:, p] @ translations[:, j, :, None])[..., 0]
    return world_pos
