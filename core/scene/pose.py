"""Local joint rotations (SMPL convention) -> Blender pose-bone channels.

A SMPL local rotation R_j acts in the armature's axes around joint j (world transform
G_j = G_parent . [R_j | offset]). A Blender pose bone's ``rotation_quaternion`` acts in the bone's
own rest frame B_j (the rotation part of ``Bone.matrix_local``). With the skinning transform of
both systems set equal, the pose-bone rotation is  Q_j = B_j^T R_j B_j  (independent of the
parent), and the root bone's ``location`` is  B_0^T transl. Quaternions are (w, x, y, z).
"""
from __future__ import annotations

import numpy as np


def axis_angle_to_matrix(aa) -> np.ndarray:
    """(..., 3) axis-angle -> (..., 3, 3) rotation matrices (Rodrigues; numpy twin of
    ``core.body.kinematics.axis_angle_to_matrix`` so the Blender side can register without torch)."""
    aa = np.asarray(aa, dtype=np.float64)
    angle = np.linalg.norm(aa, axis=-1, keepdims=True)
    axis = aa / np.where(angle < 1e-12, 1.0, angle)
    x, y, z = np.moveaxis(axis, -1, 0)
    zero = np.zeros_like(x)
    k = np.stack([zero, -z, y, z, zero, -x, -y, x, zero], -1).reshape(aa.shape[:-1] + (3, 3))
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
    """(..., 4) quaternions (w, x, y, z), any norm -> (..., 3, 3) rotation matrices."""
    q = np.asarray(q, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack([
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    ], -1).reshape(q.shape[:-1] + (3, 3))


def make_continuous(quats) -> np.ndarray:
    """(T, ..., 4) -> the same rotations with signs chosen so consecutive frames have a
    non-negative dot product (no 360-degree swings when Blender interpolates between keys)."""
    q = np.array(quats, dtype=np.float64, copy=True)
    for t in range(1, len(q)):
        flip = (q[t] * q[t - 1]).sum(-1, keepdims=True) < 0
        q[t] = np.where(flip, -q[t], q[t])
    return q


def pose_bone_quaternions(local_rotations, bone_rest) -> np.ndarray:
    """local_rotations (T,J,3,3) in armature axes, bone_rest (J,3,3) -> (T,J,4) continuous."""
    r = np.asarray(local_rotations, dtype=np.float64)
    b = np.asarray(bone_rest, dtype=np.float64)
    q = np.swapaxes(b, -1, -2)[None] @ r @ b[None]
    return make_continuous(matrix_to_quaternion(q))


def root_locations(transl, root_rest) -> np.ndarray:
    """transl (T,3) armature-space root offsets -> (T,3) root pose-bone ``location`` values."""
    return np.asarray(transl, dtype=np.float64) @ np.asarray(root_rest, dtype=np.float64)


def rebase_quaternions(quats, old_rest, new_rest) -> np.ndarray:
    """Pose-bone quaternions (T,4) keyed against rest frame ``old_rest`` (3,3) -> the quaternions
    giving the same armature-space rotation against ``new_rest`` (the bone's rest moved)."""
    d = np.asarray(new_rest, dtype=np.float64).T @ np.asarray(old_rest, dtype=np.float64)
    rot = d @ quaternion_to_matrix(quats) @ d.T
    return make_continuous(matrix_to_quaternion(rot))


def rebase_locations(locations, old_rest, new_rest) -> np.ndarray:
    """Root ``location`` keys (T,3) against ``old_rest`` -> the same offset against ``new_rest``."""
    d = np.asarray(new_rest, dtype=np.float64).T @ np.asarray(old_rest, dtype=np.float64)
    return np.asarray(locations, dtype=np.float64) @ d.T
