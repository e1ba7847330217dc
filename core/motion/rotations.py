"""Rotation helpers for the motion features: continuous 6D, rotations about Y, shortest arcs.

Conventions: rotation matrices act on column vectors (``v' = R @ v``). The continuous 6D
representation is HumanML3D's ``quaternion_to_cont6d``: the FIRST TWO COLUMNS of the matrix,
concatenated as ``(R[:,0], R[:,1]) = (R00, R10, R20, R01, R11, R21)``; its inverse is the
Gram-Schmidt of Zhou et al. (``cont6d_to_matrix``). A rotation about +Y by ``a`` radians turns +Z
towards +X: ``R_y(a) @ (0,0,1) = (sin a, 0, cos a)``.
"""
from __future__ import annotations

import numpy as np
import torch


def matrix_to_rot6d(rot):
    """(..., 3, 3) rotation matrices -> (..., 6): first two columns. numpy or torch."""
    if isinstance(rot, torch.Tensor):
        return torch.cat([rot[..., :, 0], rot[..., :, 1]], dim=-1)
    rot = np.asarray(rot)
    return np.concatenate([rot[..., :, 0], rot[..., :, 1]], axis=-1)


def rot6d_to_matrix(d6):
    """(..., 6) -> (..., 3, 3) by Gram-Schmidt (columns x, y, z). numpy or torch (differentiable)."""
    is_np = not isinstance(d6, torch.Tensor)
    t = torch.as_tensor(np.asarray(d6)) if is_np else d6
    x = torch.nn.functional.normalize(t[..., 0:3], dim=-1)
    z = torch.nn.functional.normalize(torch.linalg.cross(x, t[..., 3:6], dim=-1), dim=-1)
    y = torch.linalg.cross(z, x, dim=-1)
    out = torch.stack([x, y, z], dim=-1)
    return out.numpy() if is_np else out


def yaw_matrix(angle: np.ndarray) -> np.ndarray:
    """(...) angles in radians -> (..., 3, 3) rotations about +Y (numpy)."""
    angle = np.asarray(angle, dtype=np.float64)
    c, s = np.cos(angle), np.sin(angle)
    zero, one = np.zeros_like(c), np.ones_like(c)
    return np.stack([c, zero, s, zero, one, zero, -s, zero, c], axis=-1).reshape(angle.shape + (3, 3))


def rotation_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Shortest-arc rotation matrices taking directions u to v. (..., 3), (..., 3) -> (..., 3, 3).

    Inputs need not be unit length. For opposite directions the rotation is a half turn about an
    axis perpendicular to u.
    """
    u = np.asarray(u, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    u, v = np.broadcast_arrays(u, v)
    u = u / np.linalg.norm(u, axis=-1, keepdims=True).clip(1e-12)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True).clip(1e-12)
    axis = np.cross(u, v)
    cos = (u * v).sum(-1)
    # quaternion (w, xyz) = normalise(1 + cos, u x v): stable except at cos = -1
    q = np.concatenate([(1.0 + cos)[..., None], axis], axis=-1)
    opposite = 1.0 + cos < 1e-10
    if opposite.any():
        # any axis perpendicular to u: cross with the least-aligned basis vector
        basis = np.eye(3)[np.argmin(np.abs(u), axis=-1)]
        perp = np.cross(u, basis)
        perp /= np.linalg.norm(perp, axis=-1, keepdims=True)
        q = np.where(opposite[..., None], np.concatenate([np.zeros_like(cos)[..., None], perp], -1), q)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return quaternion_to_matrix(q)


def quaternion_to_matrix(q: np.ndarray) -> np.ndarray:
    """(..., 4) unit quaternions (w, x, y, z) -> (..., 3, 3) (numpy)."""
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=np.float64), -1, 0)
    return np.stack([
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    ], axis=-1).reshape(w.shape + (3, 3))
