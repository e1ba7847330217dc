"""Lowest heights from a few skinned vertices (core/body/sole_height.py) against the body model's
own skinning of the whole mesh, and grounding a shape change with core.body.plant.ground_shift."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from shapemove.core.body.plant import ground_shift
from shapemove.core.body.skeleton import PARENTS
from shapemove.core.body.sole_height import SOLE_BAND, lowest_heights, sole_vertices
from shapemove.core.geometry.rotations import axis_angle_to_matrix


def _forward(body, betas, poses, transl):
    with torch.no_grad():
        out = body.forward(torch.as_tensor(betas, dtype=torch.float32)[None].expand(len(poses), -1),
                           torch.as_tensor(poses, dtype=torch.float32), torch.as_tensor(transl, dtype=torch.float32))
    return out.vertices.numpy().astype(np.float64)


def _rest(body, betas):
    """(rest joints, rest vertices) for betas (10,) or (B,10), float64."""
    b = torch.as_tensor(np.asarray(betas), dtype=torch.float32).reshape(-1, 10)
    with torch.no_grad():
        j, v = body.rest_joints(b).numpy().astype(np.float64), body.rest_vertices(b).numpy().astype(np.float64)
    return (j[0], v[0]) if np.ndim(betas) == 1 else (j, v)


def _feet(body):
    """Sole vertex ids and their group: 0 left foot, 1 right foot (dominant skin joint)."""
    _, rest = _rest(body, np.zeros(10))
    w = np.asarray(body.skin_weights)
    ids = sole_vertices(rest, w, up=1)
    return ids, np.isin(w[ids].argmax(1), [8, 11]).astype(int)


def test_sole_vertices_are_the_feet_and_enough(openbody):
    _, rest = _rest(openbody, np.zeros(10))
    w = np.asarray(openbody.skin_weights)
    idx = sole_vertices(rest, w, up=1)
    band = np.flatnonzero(rest[:, 1] <= rest[:, 1].min() + SOLE_BAND)
    assert 20 < len(idx) < 0.5 * len(band) and set(idx) <= set(band)
    assert w[idx][:, [7, 8, 10, 11]].sum(1).min() > 0.5  # all on an ankle or a foot joint
    # the few kept vertices give the same lowest point as the whole band, in any pose
    rot = axis_angle_to_matrix(np.random.default_rng(4).normal(0, 0.6, (100, 24, 3)))
    joints, _ = _rest(openbody, np.zeros(10))
    args = (rot, np.zeros((100, 3)), joints, PARENTS)
    full = lowest_heights(*args, rest[band], w[band], 1, np.zeros(len(band), int))
    assert np.abs(lowest_heights(*args, rest[idx], w[idx], 1, np.zeros(len(idx), int)) - full).max() < 1e-4


def test_lowest_heights_match_the_skinned_mesh(openbody):
    rng = np.random.default_rng(1)
    betas = rng.normal(0, 1, 10)
    t = np.arange(15)[:, None, None]
    poses = rng.normal(0, 0.35, (1, 24, 3)) * np.sin(0.3 * t + rng.uniform(0, 6, (1, 24, 3)))
    transl = np.stack([0.03 * t[:, 0, 0], 0.05 * np.sin(0.4 * t[:, 0, 0]), 0.02 * t[:, 0, 0]], -1)
    joints, rest = _rest(openbody, betas)
    ids, side = _feet(openbody)
    sample = np.arange(0, len(rest), 37)
    pts, groups = np.r_[ids, sample], np.r_[side, np.full(len(sample), 2)]
    mine = lowest_heights(axis_angle_to_matrix(poses), transl, joints, PARENTS, rest[pts],
                          np.asarray(openbody.skin_weights)[pts], 1, groups)
    verts = _forward(openbody, betas, poses, transl)
    for g in range(3):
        assert np.abs(mine[:, g] - verts[:, pts[groups == g], 1].min(1)).max() < 1e-5
    # both bodies of a batch in one call
    joints2, rest2 = _rest(openbody, np.stack([betas, np.zeros(10)]))
    both = lowest_heights(axis_angle_to_matrix(poses), transl, joints2, PARENTS, rest2[:, pts],
                          np.asarray(openbody.skin_weights)[pts], 1, groups)
    assert both.shape == (2, 15, 3) and np.abs(both[0] - mine).max() < 1e-7


def test_a_taller_body_is_grounded_frame_by_frame_on_its_soles(openbody):
    # a squat in place, grounded on every frame for the first body, both feet in contact throughout
    frames = 10
    poses = np.zeros((frames, 24, 3))
    bend = np.linspace(0, 1.4, frames)
    poses[:, [1, 2], 0] = -bend[:, None]
    poses[:, [4, 5], 0] = 2 * bend[:, None]
    poses[:, [7, 8], 0] = -0.5 * bend[:, None]
    b0, b1 = np.zeros(10), np.zeros(10)
    b1[0] = 2.5
    ids, side = _feet(openbody)
    w = np.asarray(openbody.skin_weights)[ids]
    contacts = np.ones((frames, 4), np.uint8)

    def low(betas, transl):
        joints, rest = _rest(openbody, betas)
        return lowest_heights(axis_angle_to_matrix(poses), transl, joints, PARENTS, rest[ids], w, 1, side)

    transl = np.zeros((frames, 3))
    transl[:, 1] += ground_shift(low(b0, transl), low(b0, transl).min(1), contacts)
    assert np.abs(_forward(openbody, b0, poses, transl)[:, ids, 1].min(1)).max() < 1e-5
    # the same keys on a taller body: its soles go through the floor in the deep squat ...
    assert np.abs(low(b1, transl).min(1)).max() > 0.02
    # ... and plant's ground shift, from these heights, puts them back on it in every frame
    transl[:, 1] += ground_shift(low(b1, transl), low(b1, transl).min(1), contacts)
    assert np.abs(_forward(openbody, b1, poses, transl)[:, ids, 1].min(1)).max() < 1e-5
    assert ground_shift(low(b1, transl), low(b1, transl).min(1), contacts) == pytest.approx(0.0, abs=1e-9)
