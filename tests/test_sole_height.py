"""Sole heights from the skinned sole vertices (core/scene/sole_height.py) against the body
model's own skinning of the whole mesh."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from shapemove.core.body.skeleton import PARENTS
from shapemove.core.geometry.rotations import axis_angle_to_matrix
from shapemove.core.scene.sole_height import floor_shift, lowest_sole_heights, shape_change_shift, sole_vertices


def _pose(frames=15, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(frames)[:, None, None]
    poses = rng.normal(0, 0.35, (1, 24, 3)) * np.sin(0.3 * t + rng.uniform(0, 6, (1, 24, 3)))
    transl = np.stack([0.03 * t[:, 0, 0], 0.05 * np.sin(0.4 * t[:, 0, 0]), 0.02 * t[:, 0, 0]], -1)
    return poses, transl


def _forward(body, betas, poses, transl):
    with torch.no_grad():
        out = body.forward(torch.as_tensor(betas, dtype=torch.float32)[None].expand(len(poses), -1),
                           torch.as_tensor(poses, dtype=torch.float32), torch.as_tensor(transl, dtype=torch.float32))
    return out.vertices.numpy().astype(np.float64)


def _lowest(body, betas, poses, transl, idx):
    b = torch.as_tensor(betas, dtype=torch.float32)[None]
    with torch.no_grad():
        rest_j = body.rest_joints(b)[0].numpy()
        rest_v = body.rest_vertices(b)[0].numpy()
    return lowest_sole_heights(axis_angle_to_matrix(poses), transl, rest_j, PARENTS, rest_v[idx],
                               np.asarray(body.skin_weights)[idx], up=1)


def test_sole_vertices_are_the_feet(openbody):
    with torch.no_grad():
        rest = openbody.rest_vertices(torch.zeros(1, 10))[0].numpy()
    w = np.asarray(openbody.skin_weights)
    idx = sole_vertices(rest, w, up=1)
    band = np.flatnonzero(rest[:, 1] <= rest[:, 1].min() + 0.03)
    assert 20 < len(idx) < 0.5 * len(band) and set(idx) <= set(band)
    feet = w[idx][:, [7, 8, 10, 11]].sum(1)
    assert feet.min() > 0.5  # every sole vertex is mostly skinned to an ankle or a foot joint
    # the few kept vertices give the same lowest point as the whole band, in any pose
    rng = np.random.default_rng(4)
    rot = axis_angle_to_matrix(rng.normal(0, 0.6, (100, 24, 3)))
    joints = openbody.rest_joints(torch.zeros(1, 10))[0].numpy()
    args = (rot, np.zeros((100, 3)), joints, PARENTS)
    full = lowest_sole_heights(*args, rest[band], w[band], up=1)
    assert np.abs(lowest_sole_heights(*args, rest[idx], w[idx], up=1) - full).max() < 1e-4


def test_lowest_sole_heights_match_the_skinned_mesh(openbody):
    betas = np.random.default_rng(1).normal(0, 1, 10)
    poses, transl = _pose()
    with torch.no_grad():
        rest = openbody.rest_vertices(torch.as_tensor(betas, dtype=torch.float32)[None])[0].numpy()
    idx = sole_vertices(rest, openbody.skin_weights, up=1)
    mine = _lowest(openbody, betas, poses, transl, idx)
    verts = _forward(openbody, betas, poses, transl)
    assert np.abs(mine - verts[:, idx, 1].min(1)).max() < 1e-5
    # standing poses: the soles are the lowest part of the whole body
    assert np.abs(mine - verts[:, :, 1].min(1)).max() < 0.05


def _squat(frames=10):
    """Knees and hips bending deeper frame by frame, the root fixed: the soles leave the floor."""
    poses = np.zeros((frames, 24, 3))
    bend = np.linspace(0, 1.4, frames)
    poses[:, [1, 2], 0] = -bend[:, None]
    poses[:, [4, 5], 0] = 2 * bend[:, None]
    poses[:, [7, 8], 0] = -0.5 * bend[:, None]
    return poses, np.zeros((frames, 3))


def test_shifts_keep_and_put_the_soles_on_the_floor(openbody):
    poses, transl = _squat()
    b0, b1 = np.zeros(10), np.zeros(10)
    b1[0] = 2.5
    with torch.no_grad():
        rest = openbody.rest_vertices(torch.zeros(1, 10))[0].numpy()
    idx = sole_vertices(rest, openbody.skin_weights, up=1)
    # a squat grounded frame by frame for the first body (what a real motion does)
    per_frame = -_lowest(openbody, b0, poses, transl, idx)
    grounded = transl + per_frame[:, None] * [0.0, 1.0, 0.0]
    low0 = _lowest(openbody, b0, poses, grounded, idx)
    assert np.abs(_forward(openbody, b0, poses, grounded)[:, idx, 1].min(1)).max() < 1e-5
    assert floor_shift(low0 + 0.02) == pytest.approx(-0.02, abs=1e-9)
    # a taller body, same keys: its soles go through the floor in the deep squat ...
    low1 = _lowest(openbody, b1, poses, grounded, idx)
    assert np.abs(low1).max() > 0.02
    shift = shape_change_shift(low0, low1)
    # ... and the per-frame root shift puts them back on it in every frame
    after = _forward(openbody, b1, poses, grounded + shift[:, None] * [0.0, 1.0, 0.0])
    assert np.abs(after[:, idx, 1].min(1)).max() < 1e-5
    # both bodies in one batched call give the same heights
    b = torch.as_tensor(np.stack([b0, b1]), dtype=torch.float32)
    with torch.no_grad():
        joints, verts = openbody.rest_joints(b).numpy(), openbody.rest_vertices(b).numpy()
    both = lowest_sole_heights(axis_angle_to_matrix(poses), grounded, joints, PARENTS, verts[:, idx],
                               np.asarray(openbody.skin_weights)[idx], up=1)
    assert np.abs(both - np.stack([low0, low1])).max() < 1e-9
