"""Local joint rotations (SMPL convention) -> Blender pose-bone channels.

A SMPL local rotation R_j acts in the armature's axes around joint j (world transform
G_j = G_parent . [R_j | offset]). A Blender pose bone's ``rotation_quaternion`` acts in the bone's
own rest frame B_j (the rotation part of ``Bone.matrix_local``). With the skinning transform of
both systems set equal, the pose-bone rotation is  Q_j = B_j^T R_j B_j  (independent of the
parent), and the root bone's ``location`` is  B_0^T transl. Quaternions are (w, x, y, z).
"""
from __future__ import annotations

import numpy as np

from ..geometry.rotations import make_continuous, matrix_to_quaternion, quaternion_multiply


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
    """Pose-bone quaternions (..., T, 4) keyed against rest frames ``old_rest`` (..., 3, 3) -> the
    quaternions giving the same armature-space rotation against ``new_rest`` (the bone's rest moved):
    Q' = D Q D^T with D = new^T old, as the quaternion product d q d*. Each key keeps its sign, so
    continuous keys stay continuous; the rest frames should be orthonormal (float64)."""
    d = np.swapaxes(np.asarray(new_rest, dtype=np.float64), -1, -2) @ np.asarray(old_rest, dtype=np.float64)
    qd = matrix_to_quaternion(d)[..., None, :]  # one per bone, broadcast over frames
    return quaternion_multiply(quaternion_multiply(qd, quats), qd * np.array([1.0, -1.0, -1.0, -1.0]))


def rebase_locations(locations, old_rest, new_rest) -> np.ndarray:
    """Root ``location`` keys (T,3) against ``old_rest`` -> the same offset against ``new_rest``."""
    d = np.swapaxes(np.asarray(new_rest, dtype=np.float64), -1, -2) @ np.asarray(old_rest, dtype=np.float64)
    return np.asarray(locations, dtype=np.float64) @ d.T
