"""How high the body's soles are, frame by frame, from the skinned mesh (numpy, no torch).

The feet of a rig stay on the floor after a shape change when its root is moved up or down, frame
by frame, by the change of the lowest sole point (``shape_change_shift``): a foot that touched the
floor still touches it, a jump keeps its clearance. A new motion is put on the floor as a whole
(``floor_shift``). Only the sole vertices are skinned: those within
``SOLE_BAND`` of the lowest point of the rest mesh (soles, heels and toe tips in the rest
pose) that can be the lowest point (``sole_vertices``), with their full skin weights, so the
heights are exact.

Axes are the caller's (``up`` names the vertical axis: 1 for Y-up data, 2 for Blender's Z-up
armature space). Units metres.
"""
from __future__ import annotations

import numpy as np

from ..geometry.fk import forward_kinematics

SOLE_BAND = 0.03  # m above the lowest rest vertex
DIRECTIONS = 2000  # sampled directions for the extreme points of each rigid part
RIGID = 0.999  # a vertex with this much weight on one joint moves with that joint alone


def _sphere(n: int) -> np.ndarray:
    """(n,3) near-uniform unit vectors (Fibonacci sphere)."""
    i = np.arange(n) + 0.5
    polar = np.arccos(1 - 2 * i / n)
    azimuth = np.pi * (1 + 5 ** 0.5) * i
    return np.stack([np.cos(azimuth) * np.sin(polar), np.sin(azimuth) * np.sin(polar), np.cos(polar)], -1)


def sole_vertices(rest_vertices, weights, up: int, band: float = SOLE_BAND) -> np.ndarray:
    """Indices of the vertices that can be the lowest point of a foot.

    rest_vertices (V,3), weights (V,J) skin weights. The vertices within ``band`` of the lowest
    rest vertex are the soles; of those that move rigidly with one joint only the extreme points
    of each joint's set (support points in ``DIRECTIONS`` directions) can ever be the lowest, the
    blended ones are all kept. A few hundred vertices instead of a few thousand, same minimum."""
    v = np.asarray(rest_vertices, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    ids = np.flatnonzero(v[:, up] <= v[:, up].min() + band)
    w = w[ids] / np.maximum(w[ids].sum(1, keepdims=True), 1e-12)
    rigid = w.max(1) >= RIGID
    keep = [ids[~rigid]]
    dominant = w.argmax(1)
    dirs = _sphere(DIRECTIONS)
    for j in np.unique(dominant[rigid]):
        part = ids[rigid & (dominant == j)]
        keep.append(part[np.unique(np.argmin(v[part] @ dirs.T, axis=0))])
    return np.unique(np.concatenate(keep))


def _ancestors(cols, parents) -> list:
    """Sorted joints on the paths from the roots to ``cols``."""
    need = set()
    for j in cols:
        j = int(j)
        while j >= 0 and j not in need:
            need.add(j)
            j = int(parents[j])
    return sorted(need)


def lowest_sole_heights(rotations, root_offsets, rest_joints, parents, sole_rest, sole_weights, up: int) -> np.ndarray:
    """Height of the lowest sole vertex in every frame.

    rotations (T,J,3,3) local joint rotations (each joint's rest frame aligned with the axes);
    root_offsets (T,3) how far the root has moved from its rest position; rest_joints (...,J,3);
    sole_rest (...,n,3) rest positions of the sole vertices for the same body (a leading batch
    axis, e.g. two bodies, is evaluated in one pass); sole_weights (n,J) their skin weights.
    Linear blend skinning with normalised weights, as Blender's Armature modifier and BodyModel.
    Returns (...,T) metres along ``up``.
    """
    rest_joints = np.asarray(rest_joints, dtype=np.float64)
    v = np.asarray(sole_rest, dtype=np.float64)
    w = np.asarray(sole_weights, dtype=np.float64)
    w = w / np.maximum(w.sum(1, keepdims=True), 1e-12)
    cols = np.flatnonzero(np.abs(w).sum(0) > 0)  # only the joints the soles follow ...
    sub = _ancestors(cols, parents)  # ... and their chains to the root
    index = {j: i for i, j in enumerate(sub)}
    sub_parents = [index[int(parents[j])] if parents[j] >= 0 else -1 for j in sub]
    rot = np.asarray(rotations, dtype=np.float64)[:, sub]
    batch = rest_joints.shape[:-2]
    pos, world = forward_kinematics(rot[(None,) * len(batch)], rest_joints[..., None, sub, :], sub_parents)
    c = [index[int(j)] for j in cols]
    w = w[:, cols]
    a = world[..., c, up, :]  # (...,T,c,3): the up row of each joint's world rotation
    # h_ti = sum_j w_ij (a_tj . (v_i - J_j) + pos_tj,up), as four (T,c) x (c,n) products
    h = (pos[..., c, up] - (a * rest_joints[..., None, cols, :]).sum(-1)) @ w.T
    for k in range(3):
        h += a[..., k] @ np.swapaxes(w * v[..., :, k:k + 1], -1, -2)
    return h.min(axis=-1) + np.asarray(root_offsets, dtype=np.float64)[:, up]


def shape_change_shift(lowest_before, lowest_after) -> np.ndarray:
    """(T,) vertical root shift per frame that keeps the lowest sole point where it was."""
    return np.asarray(lowest_before, dtype=np.float64) - np.asarray(lowest_after, dtype=np.float64)


def floor_shift(lowest) -> float:
    """Vertical root shift that puts the lowest sole point of the motion on the floor (0)."""
    return float(-np.min(lowest))
