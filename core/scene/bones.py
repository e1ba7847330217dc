"""Bone layout of the SMPL skeleton for Blender: heads, tails, rolls and rest matrices.

Every joint gets one bone whose head sits on the joint. Its tail points at the joint's main
child (the only child, or for pelvis/spine3 the child closest to the body's mid-plane, i.e.
spine1/neck); leaf joints (head, feet, hands) continue their parent bone's direction. The roll
makes each bone's local Z axis point as close as possible to the body's forward direction (or to
"up" for bones that themselves point forward, like the feet), so the rig bends around clean axes.

``bone_matrix`` reproduces Blender's ``vec_roll_to_mat3`` (armature.cc) so the rest matrices
computed here equal ``Bone.matrix_local`` rotation parts. All arrays are float64, metres.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body.skeleton import PARENTS
from ..geometry.rotations import axis_angle_to_matrix

# In Blender axes (after ``axes.points_to_z_up``) the body faces -Y with +Z up.
FORWARD_Z_UP = (0.0, -1.0, 0.0)
UP_Z_UP = (0.0, 0.0, 1.0)


@dataclass
class BoneLayout:
    heads: np.ndarray     # (J,3) armature space
    tails: np.ndarray     # (J,3)
    rolls: np.ndarray     # (J,) radians, Blender's edit-bone roll
    matrices: np.ndarray  # (J,3,3) rest orientation of each bone in armature space (columns = bone X,Y,Z)


def main_children(rest_joints, parents=PARENTS) -> list[int | None]:
    """For each joint the child its bone points at, None for leaves.

    With several children the one nearest the mid-plane (smallest |x| offset) wins."""
    joints = np.asarray(rest_joints, dtype=np.float64)
    out: list[int | None] = []
    for j in range(len(parents)):
        kids = [c for c in range(len(parents)) if parents[c] == j]
        if not kids:
            out.append(None)
        else:
            out.append(min(kids, key=lambda c: (abs(joints[c, 0] - joints[j, 0]), c)))
    return out


def bone_matrix(vectors, rolls) -> np.ndarray:
    """Blender's vec_roll_to_mat3: (N,3) head->tail vectors and (N,) rolls -> (N,3,3) rest
    orientations (column 1 = the unit bone direction)."""
    v = np.atleast_2d(np.asarray(vectors, dtype=np.float64))
    nor = v / np.linalg.norm(v, axis=-1, keepdims=True)
    rolls = np.broadcast_to(np.asarray(rolls, dtype=np.float64), (len(nor),))
    x, y, z = nor[:, 0], nor[:, 1], nor[:, 2]
    theta = 1.0 + y
    theta_alt = x * x + z * z
    regular = (theta > 6.1e-3) | (theta_alt > 2.5e-4 ** 2)
    theta = np.where(theta <= 6.1e-3, theta_alt * 0.5 + theta_alt ** 2 * 0.125, theta)
    theta = np.where(regular, theta, 1.0)
    m = np.empty((len(nor), 3, 3))
    m[:, 0, 0] = 1 - x * x / theta
    m[:, 0, 1] = x
    m[:, 0, 2] = -x * z / theta
    m[:, 1, 0] = -x
    m[:, 1, 1] = y
    m[:, 1, 2] = -z
    m[:, 2, 0] = -x * z / theta
    m[:, 2, 1] = z
    m[:, 2, 2] = 1 - z * z / theta
    m[~regular] = np.diag([-1.0, -1.0, 1.0])
    return axis_angle_to_matrix(nor * rolls[:, None]) @ m


def roll_for_z_axis(vectors, z_targets) -> np.ndarray:
    """Rolls that turn each bone's local Z axis as close as possible to ``z_targets`` (N,3)."""
    v = np.atleast_2d(np.asarray(vectors, dtype=np.float64))
    m0 = bone_matrix(v, np.zeros(len(v)))
    t = np.atleast_2d(np.asarray(z_targets, dtype=np.float64))
    # rotating about Y = the bone direction by r: Z(r) = Z0 cos r + X0 sin r (since Y x Z = X),
    # so t . Z(r) is largest at r = atan2(t . X0, t . Z0)
    return np.arctan2(np.einsum("nk,nk->n", t, m0[:, :, 0]), np.einsum("nk,nk->n", t, m0[:, :, 2]))


def bone_layout(rest_joints, parents=PARENTS, forward=FORWARD_Z_UP, up=UP_Z_UP,
                leaf_scale: float = 0.5, min_length: float = 0.02) -> BoneLayout:
    """rest_joints (J,3) in armature space (Z-up) -> heads, tails, rolls and rest matrices.

    Leaf bones are ``leaf_scale`` times their parent bone long (at least ``min_length`` m);
    a bone shorter than ``min_length`` (coincident joints) is lengthened along its parent."""
    joints = np.asarray(rest_joints, dtype=np.float64)
    J = len(parents)
    kids = main_children(joints, parents)
    heads = joints.copy()
    tails = np.zeros_like(heads)
    for j in range(J):  # parents come first, so a leaf can read its parent's finished bone
        p = int(parents[j])
        if kids[j] is not None and np.linalg.norm(joints[kids[j]] - joints[j]) >= min_length:
            tails[j] = joints[kids[j]]
            continue
        if p >= 0:
            d = tails[p] - heads[p]
            n = np.linalg.norm(d)
            length = max(leaf_scale * n, min_length)
            tails[j] = heads[j] + d / n * length
        else:
            tails[j] = heads[j] + np.asarray(up) * max(min_length, 0.1)
    vec = tails - heads
    unit = vec / np.linalg.norm(vec, axis=-1, keepdims=True)
    fwd, upv = np.asarray(forward, dtype=np.float64), np.asarray(up, dtype=np.float64)
    targets = np.where((np.abs(unit @ fwd) < 0.7)[:, None], fwd[None], upv[None])
    rolls = roll_for_z_axis(vec, targets)
    return BoneLayout(heads=heads, tails=tails, rolls=rolls, matrices=bone_matrix(vec, rolls))
