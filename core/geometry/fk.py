"""Forward kinematics in numpy (float64), batched over any leading dimensions.

Local rotations are relative to the parent joint's frame in the rest pose: with all identities
the skeleton stands in its rest pose. ``parents`` (J,) has -1 for roots and parents[j] < j.
``torch_ops.forward_kinematics`` is the same function in torch (for gradients).
"""
from __future__ import annotations

import numpy as np


def bone_offsets(rest_joints, parents) -> np.ndarray:
    """(..., J, 3) rest joint positions -> (..., J, 3) each joint relative to its parent (a root
    keeps its position)."""
    rest = np.asarray(rest_joints, dtype=np.float64)
    par = np.asarray(parents, dtype=np.int64)
    out = rest.copy()
    child = par >= 0
    out[..., child, :] = rest[..., child, :] - rest[..., par[child], :]
    return out


def joints_from_offsets(offsets, parents) -> np.ndarray:
    """Inverse of ``bone_offsets``: (..., J, 3) offsets in the parents' frames -> positions."""
    off = np.asarray(offsets, dtype=np.float64)
    out = off.copy()
    for j, p in enumerate(parents):
        if p >= 0:
            out[..., j, :] = out[..., int(p), :] + off[..., j, :]
    return out


def forward_kinematics(rotations, rest_joints, parents) -> tuple[np.ndarray, np.ndarray]:
    """Pose a skeleton.

    rotations (..., J, 3, 3) local rotations; rest_joints (..., J, 3) rest-pose joint positions
    (broadcast against the rotations: a root whose rest position changes every frame moves the
    whole skeleton). Returns posed joints (..., J, 3), each root at its rest position, and the
    world rotations (..., J, 3, 3). The only Python loop runs over the joints, never the frames.
    """
    rot = np.asarray(rotations, dtype=np.float64)
    off = bone_offsets(rest_joints, parents)
    shape = np.broadcast_shapes(rot.shape[:-2], off.shape[:-1])
    rot = np.broadcast_to(rot, shape + (3, 3))
    off = np.broadcast_to(off, shape + (3,))
    world = np.empty(shape + (3, 3))
    pos = np.empty(shape + (3,))
    for j, p in enumerate(parents):
        p = int(p)
        if p < 0:
            world[..., j, :, :] = rot[..., j, :, :]
            pos[..., j, :] = off[..., j, :]
        else:
            world[..., j, :, :] = world[..., p, :, :] @ rot[..., j, :, :]
            pos[..., j, :] = pos[..., p, :] + (world[..., p, :, :] @ off[..., j, :, None])[..., 0]
    return pos, world
