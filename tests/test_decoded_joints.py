"""A generated motion is posed from its decoded rotations (``generation/decoded_joints.py``)."""
import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.generation.decoded_joints import decoded_joints
from shapemove.core.geometry.rotations import axis_angle_to_matrix
from shapemove.core.motion.features import feature_slices, joints_from_features, posed_features
from shapemove.core.scene.motion_file import make_motion

T = 40
BETAS = np.array([1.0, -0.5, 0.3, 0, 0, 0, 0, 0, 0, 0], np.float32)


def _features(body, contacts=None, travel=0.05, turn=0.8):
    """Features of a body turning and travelling, its arms, knees and spine bending: every block
    written from one pose, as the dataset builder writes a clip's."""
    t = np.arange(T) / T
    poses = np.zeros((T, 24, 3), np.float32)
    poses[:, 0, 1] = turn * t                           # the root turns
    poses[:, 3, 0] = 0.3 * np.sin(2 * np.pi * t)        # spine1 bends
    poses[:, 4, 0] = 0.6 * (1 - np.cos(2 * np.pi * t))  # left knee
    poses[:, 16, 2] = -0.9 * np.sin(np.pi * t)          # left shoulder lifts the arm
    poses[:, 19, 1] = 0.7 * t                           # right elbow
    transl = np.stack([0.02 * np.sin(3 * t), 0.01 * t, travel * np.arange(T)], 1).astype(np.float32)
    m = make_motion(body, poses, transl, BETAS)
    c = np.zeros((T, 4), np.uint8) if contacts is None else contacts
    return posed_features(m.joints, axis_angle_to_matrix(poses), c)


def test_consistent_features_give_their_joints_back(openbody):
    f = _features(openbody)
    got = decoded_joints(f, openbody, BETAS)
    want = joints_from_features(f.astype(np.float64))
    assert got.shape == want.shape == (T - 1, 22, 3)
    assert np.abs(got - want).max() < 2e-3   # metres: the body, its root fit and its path agree


def test_the_upper_body_comes_from_the_rotations_the_legs_from_the_positions(openbody):
    f = _features(openbody)
    moved = f.copy()
    ric = moved[:, feature_slices["ric"]].reshape(T - 1, 21, 3)
    ric[:, [19, 20], 1] += 0.2     # the decoded wrists 20 cm higher (ric holds joints 1..21)
    ric[:, [6, 7], 2] += 0.1       # the decoded ankles 10 cm forward
    moved[:, feature_slices["ric"]] = ric.reshape(T - 1, -1)
    was, now = joints_from_features(f.astype(np.float64)), joints_from_features(moved.astype(np.float64))
    assert np.abs(now[:, 20:22, 1] - was[:, 20:22, 1]).min() > 0.19
    got, before = decoded_joints(moved, openbody, BETAS), decoded_joints(f, openbody, BETAS)
    np.testing.assert_allclose(got[:, 12:], before[:, 12:], atol=1e-3)       # neck, head, collars, arms: rotations
    np.testing.assert_allclose(got[:, [7, 8]], now[:, [7, 8]], atol=1e-9)    # ankles: where the positions put them


def test_the_path_is_the_decoded_pelvis(openbody):
    """The pelvis travels as the decoded positions say (here 5 cm a frame more than the pose
    did), whatever the rotations' legs do."""
    f = _features(openbody, travel=0.0, turn=0.0)
    fast = f.copy()
    fast[:, 2] += 0.05             # root linear velocity (z, the root's forward axis)
    want = joints_from_features(fast.astype(np.float64))[:, 0]
    assert np.linalg.norm(want[-1, [0, 2]] - want[0, [0, 2]]) > 1.5
    np.testing.assert_allclose(decoded_joints(fast, openbody, BETAS)[:, 0], want, atol=1e-6)


def test_bad_features_are_refused(openbody):
    with pytest.raises(ShapeMoveError, match="finite"):
        decoded_joints(np.zeros((5, 200)), openbody, BETAS)
    bad = _features(openbody)
    bad[3, 70] = np.nan
    with pytest.raises(ShapeMoveError, match="finite"):
        decoded_joints(bad, openbody, BETAS)
