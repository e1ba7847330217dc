"""How low the body's mesh reaches, frame by frame, from a few skinned vertices (numpy, no torch).

A rig's feet are kept on the floor after a shape change by ``core.body.plant.ground_shift``,
which needs, per frame, the lowest point of each foot's sole and of the whole body. Those come
from here for any pose of the keyed motion: the sole vertices (``sole_vertices``: within
``SOLE_BAND`` of the lowest rest vertex, reduced to those that can ever be lowest) and a sparse
sample of the rest of the body, skinned with their full weights (``lowest_heights``), so the
sole heights are exact.

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


def lowest_heights(rotations, root_offsets, rest_joints, parents, points_rest, weights, up: int, groups) -> np.ndarray:
    """Height of the lowest point of each group of skinned points, in every frame.

    rotations (T,J,3,3) local joint rotations (each joint's rest frame aligned with the axes);
    root_offsets (T,3) how far the root has moved from its rest position; rest_joints (...,J,3);
    points_rest (...,n,3) rest positions of the points on the same body (a leading batch axis,
    e.g. two bodies, is evaluated in one pass); weights (n,J) their skin weights; groups (n,) int
    group of each point, 0..G-1. Linear blend skinning with normalised weights, as Blender's
    Armature modifier and BodyModel. Returns (...,T,G) metres along ``up``.
    """
    rest_joints = np.asarray(rest_joints, dtype=np.float64)
    groups = np.asarray(groups, dtype=np.int64)
    order = np.argsort(groups, kind="stable")  # each group one contiguous slice
    groups = groups[order]
    v = np.asarray(points_rest, dtype=np.float64)[..., order, :]
    w = np.asarray(weights, dtype=np.float64)[order]
    w = w / np.maximum(w.sum(1, keepdims=True), 1e-12)
    cols = np.flatnonzero(np.abs(w).sum(0) > 0)  # only the joints the points follow ...
    sub = _ancestors(cols, parents)  # ... and their chains to the root
    index = {j: i for i, j in enumerate(sub)}
    sub_parents = [index[int(parents[j])] if parents[j] >= 0 else -1 for j in sub]
    rot = np.asarray(rotations, dtype=np.float64)[:, sub]
    batch = rest_joints.shape[:-2]
    pos, world = forward_kinematics(rot[(None,) * len(batch)], rest_joints[..., None, sub, :], sub_parents)
    c = [index[int(j)] for j in cols]
    w = w[:, cols]
    a = world[..., c, up, :]  # (...,T,c,3): the up row of each joint's world rotation
    # h_ti = sum_j w_ij (a_tj . (v_i - J_j) + pos_tj,up), as four (T,c) x (c,n) products; float32
    # for speed (heights of a few metres: 0.1 um steps)
    f32 = np.float32
    h = (pos[..., c, up] - (a * rest_joints[..., None, cols, :]).sum(-1)).astype(f32) @ w.T.astype(f32)
    for k in range(3):
        h += a[..., k].astype(f32) @ np.swapaxes(w * v[..., :, k:k + 1], -1, -2).astype(f32)
    bounds = np.searchsorted(groups, np.arange(int(groups.max()) + 2))
    out = np.stack([h[..., s:e].min(axis=-1) if e > s else np.full(h.shape[:-1], np.inf, f32)
                    for s, e in zip(bounds[:-1], bounds[1:])], -1).astype(np.float64)
    return out + np.asarray(root_offsets, dtype=np.float64)[:, up, None]
