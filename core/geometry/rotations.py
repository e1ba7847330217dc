"""Rotations in numpy (float64), the one definition of each conversion in the project.

Conventions: matrices act on column vectors (``v' = R @ v``); quaternions are (w, x, y, z);
axis-angle is the rotation axis times the angle in radians; the continuous 6D representation is
HumanML3D's: the FIRST TWO COLUMNS of the matrix, ``(R00, R10, R20, R01, R11, R21)``, and its
inverse is the Gram-Schmidt of Zhou et al. A rotation about +Y by ``a`` turns +Z towards +X:
``yaw_matrix(a) @ (0,0,1) = (sin a, 0, cos a)``. Torch twins (for gradients) live in
``torch_ops`` under the same names.
"""
from __future__ import annotations

import numpy as np


def _skew(v: np.ndarray) -> np.ndarray:
    """(..., 3) -> (..., 3, 3) cross-product matrices [v]x."""
    x, y, z = np.moveaxis(v, -1, 0)
    zero = np.zeros_like(x)
    return np.stack([zero, -z, y, z, zero, -x, -y, x, zero], -1).reshape(v.shape[:-1] + (3, 3))


def axis_rotation(axis: str, angles) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about ``axis`` ('x', 'y' or 'z') by ``angles`` radians (...)."""
    angles = np.asarray(angles, dtype=np.float64)
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
    return np.stack(rows, axis=-1).reshape(angles.shape + (3, 3))


def yaw_matrix(angle) -> np.ndarray:
    """(...) angles in radians -> (..., 3, 3) rotations about +Y."""
    return axis_rotation("y", angle)


def euler_matrix(axes: str, angles) -> np.ndarray:
    """Intrinsic Euler rotation: ``axes`` like 'zxy', angles (..., len(axes)) radians.

    R = R_axes[0] @ R_axes[1] @ ... (the BVH convention: channels listed outermost first)."""
    angles = np.asarray(angles, dtype=np.float64)
    out = np.broadcast_to(np.eye(3), (*angles.shape[:-1], 3, 3)).copy()
    for k, ax in enumerate(axes):
        out = out @ axis_rotation(ax, angles[..., k])
    return out


def axis_angle_to_matrix(aa) -> np.ndarray:
    """(..., 3) axis-angle -> (..., 3, 3) rotation matrices (Rodrigues), exact at angle 0."""
    aa = np.asarray(aa, dtype=np.float64)
    angle = np.linalg.norm(aa, axis=-1, keepdims=True)
    k = _skew(aa / np.where(angle < 1e-12, 1.0, angle))
    s, c = np.sin(angle)[..., None], np.cos(angle)[..., None]
    return np.eye(3) + s * k + (1 - c) * (k @ k)


def matrix_to_quaternion(rot) -> np.ndarray:
    """(..., 3, 3) rotation matrices -> (..., 4) unit quaternions (w, x, y, z), w >= 0."""
    r = np.asarray(rot, dtype=np.float64)
    m00, m11, m22 = r[..., 0, 0], r[..., 1, 1], r[..., 2, 2]
    # Shepperd: pick the largest of 4w^2, 4x^2, 4y^2, 4z^2 for a well-conditioned square root
    cands = np.stack([1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22], -1)
    k = cands.argmax(-1)
    s = np.sqrt(np.maximum(np.take_along_axis(cands, k[..., None], -1)[..., 0], 1e-300)) * 2  # 4*|q_k|
    q = np.empty(r.shape[:-2] + (4,))
    d21, d02, d10 = r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]
    s01, s02, s12 = r[..., 0, 1] + r[..., 1, 0], r[..., 0, 2] + r[..., 2, 0], r[..., 1, 2] + r[..., 2, 1]
    options = [
        np.stack([s / 4, d21 / s, d02 / s, d10 / s], -1),
        np.stack([d21 / s, s / 4, s01 / s, s02 / s], -1),
        np.stack([d02 / s, s01 / s, s / 4, s12 / s], -1),
        np.stack([d10 / s, s02 / s, s12 / s, s / 4], -1),
    ]
    for i, opt in enumerate(options):
        q = np.where((k == i)[..., None], opt, q)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


def quaternion_to_matrix(q) -> np.ndarray:
    """(..., 4) quaternions (w, x, y, z), any non-zero norm -> (..., 3, 3) rotation matrices."""
    q = np.asarray(q, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack([
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    ], -1).reshape(q.shape[:-1] + (3, 3))


def matrix_to_axis_angle(rot) -> np.ndarray:
    """(..., 3, 3) rotation matrices -> (..., 3) axis-angle with angle in [0, pi], robust near 0
    and pi (through the quaternion)."""
    q = matrix_to_quaternion(rot)  # w >= 0: angle = 2 atan2(|v|, w) in [0, pi]
    v = q[..., 1:]
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    angle = 2 * np.arctan2(n, q[..., :1])
    # small angles: angle / sin(angle/2) -> 2
    scale = np.where(n < 1e-12, 2.0, angle / np.where(n < 1e-12, 1.0, n))
    return v * scale


def quaternion_multiply(a, b) -> np.ndarray:
    """Hamilton product of quaternions (..., 4) (w, x, y, z), broadcast: the rotation b, then a."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], -1)


def make_continuous(quats) -> np.ndarray:
    """(T, ..., 4) -> the same rotations with signs chosen so consecutive frames have a
    non-negative dot product (no 360-degree swings when interpolating between keys)."""
    q = np.array(quats, dtype=np.float64, copy=True)
    for t in range(1, len(q)):
        flip = (q[t] * q[t - 1]).sum(-1, keepdims=True) < 0
        q[t] = np.where(flip, -q[t], q[t])
    return q


def slerp(q0, q1, w) -> np.ndarray:
    """Spherical interpolation of unit quaternions (..., 4) with weights w (...) in [0, 1] along
    the shortest arc; constant angular velocity in w."""
    q0 = np.asarray(q0, dtype=np.float64)
    q1 = np.asarray(q1, dtype=np.float64)
    w = np.asarray(w, dtype=np.float64)
    dot = np.sum(q0 * q1, -1)
    q1 = np.where(dot[..., None] < 0, -q1, q1)
    theta = np.arccos(np.clip(np.abs(dot), 0.0, 1.0))
    s = np.sin(theta)
    small = s < 1e-6
    a = np.where(small, 1 - w, np.sin((1 - w) * theta) / np.where(small, 1, s))
    b = np.where(small, w, np.sin(w * theta) / np.where(small, 1, s))
    q = a[..., None] * q0 + b[..., None] * q1
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def matrix_to_rot6d(rot) -> np.ndarray:
    """(..., 3, 3) rotation matrices -> (..., 6): the first two columns."""
    rot = np.asarray(rot)
    return np.concatenate([rot[..., :, 0], rot[..., :, 1]], axis=-1)


def rot6d_to_matrix(d6) -> np.ndarray:
    """(..., 6) -> (..., 3, 3) by Gram-Schmidt (columns x, y, z)."""
    d6 = np.asarray(d6, dtype=np.float64)
    x = d6[..., 0:3] / np.linalg.norm(d6[..., 0:3], axis=-1, keepdims=True).clip(1e-12)
    z = np.cross(x, d6[..., 3:6])
    z = z / np.linalg.norm(z, axis=-1, keepdims=True).clip(1e-12)
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=-1)


def rotation_between(u, v) -> np.ndarray:
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
    return quaternion_to_matrix(q)


def orthonormal_frame(a, b) -> np.ndarray:
    """(..., 3, 3) frame with columns [a, b made orthogonal to a, a x b] (unit); for b parallel to
    a any perpendicular is used. ``orthonormal_frame(b1, b2) @ orthonormal_frame(a1, a2).T`` takes
    a1 onto b1's direction and a2 as close as it can to b2."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    a, b = np.broadcast_arrays(a, b)
    e1 = a / np.linalg.norm(a, axis=-1, keepdims=True).clip(1e-9)
    b = b - (b * e1).sum(-1, keepdims=True) * e1
    alt = np.where(np.abs(e1[..., :1]) < 0.9, [1.0, 0, 0], [0, 1.0, 0])
    alt = alt - (alt * e1).sum(-1, keepdims=True) * e1
    e2 = np.where(np.linalg.norm(b, axis=-1, keepdims=True) < 1e-7, alt, b)
    e2 = e2 / np.linalg.norm(e2, axis=-1, keepdims=True).clip(1e-9)
    return np.stack([e1, e2, np.cross(e1, e2)], axis=-1)
