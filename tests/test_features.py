"""HumanML3D 263-dim features: hand-derived values on constructed motions, round trips on real clips."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.geometry.rotations import matrix_to_rot6d, rot6d_to_matrix, rotation_between, yaw_matrix
from shapemove.core.io.mocap import load_smpl22
from shapemove.core.motion import (canonicalize, feature_slices, features_from_joints,
                                   joints_from_features, local_rotations_from_joints, mean_std)
from shapemove.core.motion.features import T2M_RAW_OFFSETS, _CHILD, _PARENTS
from shapemove.core.motion.skeleton_ops import gaussian_smooth

S = feature_slices

# An SMPL-like rest skeleton (metres, Y up, facing +Z, left at +X); lowest joint (feet) at y=0.02.
REST = np.array([
    [0.00, 0.93, 0.00], [0.06, 0.84, 0.00], [-0.06, 0.84, 0.00], [0.00, 1.05, -0.01],
    [0.10, 0.47, 0.00], [-0.10, 0.47, 0.00], [0.00, 1.18, 0.01], [0.09, 0.07, -0.04],
    [-0.09, 0.07, -0.04], [0.00, 1.24, 0.01], [0.12, 0.02, 0.08], [-0.12, 0.02, 0.08],
    [0.00, 1.45, -0.02], [0.08, 1.36, -0.01], [-0.08, 1.36, -0.01], [0.00, 1.51, 0.03],
    [0.18, 1.38, -0.02], [-0.18, 1.38, -0.02], [0.43, 1.37, -0.04], [-0.43, 1.37, -0.04],
    [0.68, 1.37, -0.03], [-0.68, 1.37, -0.03]])


def rigid_motion(yaw, translation):
    """REST turned by yaw[t] about Y then moved by translation[t]: (T, 22, 3)."""
    return np.einsum("tij,kj->tki", yaw_matrix(np.asarray(yaw)), REST) + np.asarray(translation)[:, None]


# ---------------------------------------------------------------- constructed motions

def test_layout_is_263():
    sizes = {k: s.stop - s.start for k, s in S.items()}
    assert sizes == {"root_rot_vel": 1, "root_lin_vel": 2, "root_y": 1, "ric": 63, "rot6d": 126,
                     "local_vel": 66, "contacts": 4}
    assert S["contacts"].stop == 263


def test_translation_at_one_metre_per_second_along_z():
    T = 40
    t = np.arange(T)
    joints = rigid_motion(np.zeros(T), np.stack([np.zeros(T), np.zeros(T) + 0.5, t / 20.0], -1))
    f = features_from_joints(joints)
    assert f.shape == (T - 1, 263) and f.dtype == np.float32
    np.testing.assert_allclose(f[:, S["root_rot_vel"]], 0, atol=1e-7)
    np.testing.assert_allclose(f[:, S["root_lin_vel"]], np.tile([0.0, 0.05], (T - 1, 1)), atol=1e-6)
    np.testing.assert_allclose(f[:, S["root_y"]], 0.93 - 0.02, atol=1e-6)   # floor = lowest joint
    ric = f[:, S["ric"]].reshape(T - 1, 21, 3)
    expected = REST[1:] - REST[0] * [1, 0, 1] - [0, 0.02, 0]
    np.testing.assert_allclose(ric, np.broadcast_to(expected, ric.shape), atol=1e-6)
    vel = f[:, S["local_vel"]].reshape(T - 1, 22, 3)
    np.testing.assert_allclose(vel, np.broadcast_to([0, 0, 0.05], vel.shape), atol=1e-6)
    # 0.05 m/frame -> 0.0025 m^2 > 0.002: flying feet, no contact
    np.testing.assert_array_equal(f[:, S["contacts"]], 0)


def test_contacts_threshold_on_squared_displacement():
    T = 10
    slow = rigid_motion(np.zeros(T), np.stack([np.zeros(T), np.zeros(T), 0.04 * np.arange(T)], -1))
    np.testing.assert_array_equal(features_from_joints(slow)[:, S["contacts"]], 1)  # 0.0016 < 0.002
    fast = rigid_motion(np.zeros(T), np.stack([np.zeros(T), np.zeros(T), 0.046 * np.arange(T)], -1))
    np.testing.assert_array_equal(features_from_joints(fast)[:, S["contacts"]], 0)  # 0.0021 > 0.002
    # only the left foot lifts: columns are l_ankle, l_foot, r_ankle, r_foot
    still = rigid_motion(np.zeros(T), np.zeros((T, 3)))
    still[:, 10, 1] += 0.1 * np.arange(T)
    np.testing.assert_array_equal(features_from_joints(still)[0, S["contacts"]], [1, 0, 1, 1])


def test_turning_in_place_at_constant_rate():
    rate = 0.6  # rad/s, turning left (+Z towards +X)
    T = 240
    joints = rigid_motion(rate * np.arange(T) / 20.0, np.zeros((T, 3)))
    # unsmoothed root frame: exact for every row. HumanML3D stores HALF the per-frame angle of the
    # world->root rotation: -rate / 20 / 2
    f = features_from_joints(joints, smooth_sigma=0)
    np.testing.assert_allclose(f[:, 0], -rate / 20 / 2, atol=1e-7)
    # default (HumanML3D's 20-frame Gaussian on the facing): same where the window is inside the clip
    f = features_from_joints(joints)
    np.testing.assert_allclose(f[81:T - 82, 0], -rate / 20 / 2, atol=1e-6)
    # in the root frame the body never moves: ric is the rest pose every frame
    ric = features_from_joints(joints, smooth_sigma=0)[:, S["ric"]].reshape(T - 1, 21, 3)
    np.testing.assert_allclose(ric, np.broadcast_to(ric[0], ric.shape), atol=1e-6)
    rec = joints_from_features(f)
    np.testing.assert_allclose(rec, canonicalize(joints)[:-1], atol=1e-5)


def test_heading_crossing_180_degrees_is_a_small_step():
    T = 30
    yaw = np.pi - 0.2 + 0.02 * np.arange(T)  # crosses +-pi mid-clip
    f = features_from_joints(rigid_motion(yaw, np.zeros((T, 3))), smooth_sigma=0)
    np.testing.assert_allclose(f[:, 0], -0.01, atol=1e-7)


def test_motion_facing_minus_x_is_turned_to_face_plus_z():
    T = 20
    yaw = np.full(T, -np.pi / 2)  # R_y(-pi/2) turns +Z into -X
    start = np.array([3.0, 0.3, -2.0])
    walk = start + np.arange(T)[:, None] / 20.0 * np.array([-1.0, 0.0, 0.0])  # forward = -X
    joints = rigid_motion(yaw, walk)
    f = features_from_joints(joints)
    np.testing.assert_allclose(f[:, S["root_lin_vel"]], np.tile([0, 0.05], (T - 1, 1)), atol=1e-6)
    rec = joints_from_features(f)
    rest_on_floor = REST - REST[0] * [1, 0, 1] - [0, 0.02, 0]
    np.testing.assert_allclose(rec[0], rest_on_floor, atol=1e-6)
    np.testing.assert_allclose(rec[-1], rest_on_floor + [0, 0, (T - 2) / 20.0], atol=1e-5)


def test_given_rotations_are_stored_as_first_two_columns():
    T = 5
    rng = np.random.default_rng(0)
    local = rotation_between(rng.normal(size=(T, 22, 3)), rng.normal(size=(T, 22, 3)))
    joints = rigid_motion(np.zeros(T), np.zeros((T, 3)))
    f = features_from_joints(joints, local_rotations=local)
    rot6d = f[:, S["rot6d"]].reshape(T - 1, 21, 6)
    np.testing.assert_allclose(rot6d[..., :3], local[:-1, 1:, :, 0], atol=1e-6)
    np.testing.assert_allclose(rot6d[..., 3:], local[:-1, 1:, :, 1], atol=1e-6)
    np.testing.assert_allclose(rot6d_to_matrix(rot6d.astype(np.float64)), local[:-1, 1:], atol=1e-6)


def test_rotations_from_positions_rest_pose_is_identity():
    T = 3
    joints = rigid_motion(np.full(T, 0.7), np.zeros((T, 3)))
    f = features_from_joints(joints, rest_joints=REST, smooth_sigma=0)
    np.testing.assert_allclose(f[:, S["rot6d"]], np.tile([1, 0, 0, 0, 1, 0], (T - 1, 21)), atol=1e-6)


def test_mean_std_groups_and_feat_bias():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(30, 263)) * np.linspace(0.5, 2.0, 263)
    b = rng.normal(size=(20, 263)) + 1.0
    a[:, S["contacts"]] = 0.0
    b[:, S["contacts"]] = 0.0  # never a contact: std 0 -> 1
    mean, std = mean_std([a, b])
    data = np.concatenate([a, b])
    np.testing.assert_allclose(mean, data.mean(0), rtol=1e-5)
    ric_std = data[:, S["ric"]].std(0).mean()
    np.testing.assert_allclose(std[S["ric"]], ric_std, rtol=1e-5)
    np.testing.assert_allclose(std[S["root_lin_vel"]], data[:, 1:3].std(0).mean(), rtol=1e-5)
    np.testing.assert_array_equal(std[S["contacts"]], 1.0)
    _, std5 = mean_std([a, b], feat_bias=5.0)
    np.testing.assert_allclose(std5[S["root_y"]], std[S["root_y"]] / 5, rtol=1e-6)
    np.testing.assert_allclose(std5[S["local_vel"]], std[S["local_vel"]], rtol=1e-6)
    with pytest.raises(ShapeMoveError):
        mean_std([np.zeros((3, 262))])


def test_bad_input_is_a_shapemove_error():
    with pytest.raises(ShapeMoveError, match="joints"):
        features_from_joints(np.zeros((10, 21, 3)))
    with pytest.raises(ShapeMoveError, match="2 frames"):
        features_from_joints(rigid_motion([0.0], np.zeros((1, 3))))
    with pytest.raises(ShapeMoveError, match="local_rotations"):
        features_from_joints(rigid_motion(np.zeros(4), np.zeros((4, 3))), np.zeros((3, 22, 3, 3)))
    with pytest.raises(ShapeMoveError, match="263"):
        joints_from_features(np.zeros((5, 262)))


def test_gaussian_matches_scipy():
    import scipy.ndimage as scipy_ndimage
    x = np.random.default_rng(2).normal(size=(50, 3))  # shorter than the 81-frame radius too
    for sigma in (20.0, 3.0):
        np.testing.assert_allclose(gaussian_smooth(x, sigma),
                                   scipy_ndimage.gaussian_filter1d(x, sigma, axis=0, mode="nearest"),
                                   atol=1e-12)


def test_joints_from_features_torch_batched_and_differentiable():
    T = 12
    joints = rigid_motion(0.3 * np.arange(T) / 20, np.stack([np.zeros(T), np.zeros(T), np.arange(T) / 20], -1))
    f = torch.tensor(np.stack([features_from_joints(joints), features_from_joints(joints[::-1].copy())]),
                     requires_grad=True)
    out = joints_from_features(f)
    assert out.shape == (2, T - 1, 22, 3) and out.dtype == torch.float32
    np.testing.assert_allclose(out[1].detach().numpy(), joints_from_features(f[1].detach().numpy()), atol=1e-6)
    out[..., 5, :].sum().backward()
    assert torch.isfinite(f.grad).all() and f.grad[:, :, 0].abs().sum() > 0  # heading drives positions
    assert f.grad[:, :, S["rot6d"]].abs().sum() == 0


# ---------------------------------------------------------------- real clips

CLIPS = ["bandai/dataset-2/data/dataset-2_walk-turn-left_active_041.bvh",
         "bandai/dataset-2/data/dataset-2_run_feminine_021.bvh",
         "bandai/dataset-1/data/dataset-1_bow_active_001.bvh"]


@pytest.fixture(scope="module")
def real_clips(mocap_root):
    return [np.asarray(load_smpl22(Path(mocap_root) / c, fps=20).joints, dtype=np.float64) for c in CLIPS]


def test_round_trip_on_real_clips(real_clips):
    for joints in real_clips:
        assert joints.shape[0] > 40
        f = features_from_joints(joints)
        assert np.isfinite(f).all()
        err = np.abs(joints_from_features(f) - canonicalize(joints)[:-1]).max()
        assert err < 1e-5, err
        # torch float32 path agrees
        rec_t = joints_from_features(torch.from_numpy(f)).numpy()
        assert np.abs(rec_t - canonicalize(joints)[:-1]).max() < 1e-5


def test_features_ignore_where_the_clip_is_placed(real_clips):
    joints = real_clips[0]
    moved = joints @ yaw_matrix(2.3).T + [4.0, 0.7, -9.0]
    np.testing.assert_allclose(features_from_joints(moved), features_from_joints(joints), atol=2e-5)


def test_canonical_clip_faces_plus_z_on_the_floor(real_clips):
    for joints in real_clips:
        c = canonicalize(joints)
        assert abs(c[..., 1].min()) < 1e-12
        np.testing.assert_allclose(c[0, 0, [0, 2]], 0, atol=1e-12)
        across = (c[0, 2] - c[0, 1]) + (c[0, 17] - c[0, 16])
        assert abs(across[2]) < 1e-9 and across[0] < 0  # right side at -X: faces +Z


def test_swing_rotations_reproduce_bone_directions(real_clips):
    joints = canonicalize(real_clips[1])
    heading = np.zeros(len(joints))
    for rest in (None, REST):
        local = local_rotations_from_joints(joints, heading, rest)
        # decode through the stored 6D and chain the rotations down the tree
        local = rot6d_to_matrix(matrix_to_rot6d(local))
        world = [yaw_matrix(heading)]
        for j in range(1, 22):
            world.append(world[_PARENTS[j]] @ local[:, j])
        for j, c in _CHILD.items():
            if c is None or j == 0:
                continue
            rest_dir = T2M_RAW_OFFSETS[c] if rest is None else REST[c] - REST[j]
            rest_dir = rest_dir / np.linalg.norm(rest_dir)
            got = np.einsum("tij,j->ti", world[j], rest_dir)
            bone = joints[:, c] - joints[:, j]
            np.testing.assert_allclose(got, bone / np.linalg.norm(bone, axis=-1, keepdims=True), atol=1e-6)


def test_the_height_column_of_a_joint():
    """The head's height is ric's 15th joint's y (4 + 3 x 14 + 1 = 47); the root's is not in ric."""
    import pytest

    from shapemove.core.errors import ShapeMoveError
    from shapemove.core.motion.features import height_column

    assert height_column(15) == 47 and height_column(1) == 5 and height_column(21) == 65
    for bad in (0, 22):
        with pytest.raises(ShapeMoveError, match="joints 1..21"):
            height_column(bad)
