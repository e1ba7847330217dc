"""Per-skeleton joint-offset calibration (core/body/joint_offsets.py): a skeleton whose torso and
girdle joints sit a known constant offset from the body's joint centres is solved to ~0 marker
error with that offset recovered; offsets are bounded; real clips of each archive reach <= 1.5 cm
marker error on their fitted OpenBody."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from shapemove.core.body.joint_offsets import (CALIBRATED_JOINTS, MAX_OFFSET, calibrate_offsets, marker_points,
                                               solve_ik_calibrated)
from shapemove.core.body.skeleton import JOINT_INDEX as J
from shapemove.core.body.skeleton import PARENTS
from shapemove.core.errors import ShapeMoveError
from shapemove.core.geometry.torch_ops import axis_angle_to_matrix


@pytest.fixture(scope="module")
def rest(openbody):
    betas = torch.tensor([[0.6, -0.4, 0.2, 0.0, 0.3, -0.2, 0.0, 0.1, 0.0, -0.2]])
    return openbody.rest_joints(betas)[0].double().numpy()


def motion(frames=60, seed=0):
    """Smooth random local rotations (frames,24,3,3) and translations (frames,3)."""
    from shapemove.bench.ik import smooth_rotations

    aa = smooth_rotations(frames, seed, amplitude=0.5)
    transl = np.stack([np.linspace(0, 1, frames), np.zeros(frames), np.linspace(0, 0.5, frames)], -1)
    return axis_angle_to_matrix(aa).numpy(), transl


def shifted_skeleton(rest, offsets, frames=60):
    """Mocap joints whose joints sit ``offsets`` (22,3) from the body's joint centres, carried by
    each joint's parent segment: what a rig with other joint definitions records."""
    R, tr = motion(frames)
    return marker_points(R, tr, rest, offsets)


KNOWN = np.zeros((22, 3))
KNOWN[J["left_shoulder"]] = [0.03, 0.01, 0.0]    # shoulders 3 cm further out, 1 cm up
KNOWN[J["right_shoulder"]] = [-0.03, 0.01, 0.0]
KNOWN[J["neck"]] = [0.0, -0.02, 0.015]           # neck 2.5 cm low and forward
KNOWN[J["left_collar"]] = [-0.015, 0.0, 0.01]


def test_recovers_known_offsets_and_reaches_zero_error(rest):
    joints = shifted_skeleton(rest, KNOWN)
    plain = solve_ik_calibrated(joints, rest, offsets=np.zeros((22, 3)))
    assert plain.marker_error_cm > 0.3  # without calibration the shifted joints are missed
    res = solve_ik_calibrated(joints, rest)
    assert res.marker_error_cm < 0.1    # the calibrated points reach the mocap
    # a joint on a segment with one child (collar -> shoulder) is known up to a constant turn of
    # that segment (the pose absorbs it): what is determined is its distance from the parent joint
    k = J["right_shoulder"]
    bone = rest[k] - rest[PARENTS[k]]
    assert np.linalg.norm(bone + res.offsets[k]) == pytest.approx(np.linalg.norm(bone + KNOWN[k]), abs=0.002)
    assert res.offset_cm[k] == pytest.approx(np.linalg.norm(KNOWN[k]) * 100, abs=0.5)
    # the joint centres are where the body's are: the raw error is about the offsets themselves
    assert res.raw_error_cm == pytest.approx(np.linalg.norm(KNOWN, axis=-1).mean() * 100, abs=0.15)
    # limbs are never calibrated
    limbs = [k for k in range(22) if k not in CALIBRATED_JOINTS]
    assert np.all(res.offsets[limbs] == 0)


def test_recovers_an_identifiable_hip_offset(rest):
    """A hip on the pelvis, whose turn the other hip and spine1 pin: the offset itself comes back."""
    known = np.zeros((22, 3))
    known[J["left_hip"]] = [0.02, 0.015, 0.0]
    res = solve_ik_calibrated(shifted_skeleton(rest, known), rest)
    assert np.abs(res.offsets[J["left_hip"]] - known[J["left_hip"]]).max() < 0.003
    assert np.abs(np.delete(res.offsets, J["left_hip"], 0)).max() < 0.003
    assert res.marker_error_cm < 0.05


def test_exact_skeleton_gets_no_offsets(rest):
    joints = shifted_skeleton(rest, np.zeros((22, 3)), frames=30)
    d = calibrate_offsets(joints, rest)
    assert np.linalg.norm(d, axis=-1).max() < 1e-3
    assert solve_ik_calibrated(joints, rest, offsets=d).marker_error_cm < 0.05


def test_offsets_are_bounded(rest):
    far = np.zeros((22, 3))
    far[J["left_shoulder"]] = [0.12, 0.0, 0.0]  # 12 cm: beyond the bound
    far[J["head"]] = [0.0, 0.09, 0.05]
    d = calibrate_offsets(shifted_skeleton(rest, far, frames=30), rest)
    n = np.linalg.norm(d, axis=-1)
    assert n.max() <= MAX_OFFSET + 1e-9
    assert n[J["left_shoulder"]] == pytest.approx(MAX_OFFSET, abs=1e-6)
    d2 = calibrate_offsets(shifted_skeleton(rest, far, frames=30), rest, max_offset=0.02)
    assert np.linalg.norm(d2, axis=-1).max() <= 0.02 + 1e-9


def test_bad_input_is_refused(rest):
    with pytest.raises(ShapeMoveError):
        calibrate_offsets(np.zeros((5, 7, 3)), rest)
    with pytest.raises(ShapeMoveError):
        calibrate_offsets(np.full((5, 22, 3), np.nan), rest)
    with pytest.raises(ShapeMoveError):
        solve_ik_calibrated(np.zeros((5, 22, 3)), rest, offsets=np.zeros((3, 3)))
    with pytest.raises(ShapeMoveError):
        calibrate_offsets(np.zeros((5, 22, 3)), rest, calibrated=[40])
    with pytest.raises(ShapeMoveError):
        calibrate_offsets(np.zeros((5, 22, 3)), rest, calibrated=["nose"])


ARCHIVE_SAMPLE = {"bandai": "dataset-1/data/dataset-1_walk-back_active_001.bvh", "hdm05": "mm/HDM_mm_grabHighR_*.amc",
                  "cmu": "bvh/02/*.bvh"}


@pytest.mark.parametrize("archive", sorted(ARCHIVE_SAMPLE))
def test_real_clip_marker_error_per_archive(mocap_root, openbody, archive):
    """The builder's fit and calibrated IK on one real clip per archive (120 frames): marker
    error <= 1.5 cm; the raw joint-centre error stays below 3 cm and the offsets within bounds."""
    from shapemove.core.body.fit import fit_betas_to_clip
    from shapemove.core.io.mocap import load_mocap
    from shapemove.core.io.resample import resample_positions
    from shapemove.core.io.rig_map import OPENBODY_LAYOUT, detect_rig, mapping_matrix

    path = sorted((mocap_root / archive).glob(ARCHIVE_SAMPLE[archive]))[0]
    m = load_mocap(path)
    W = mapping_matrix(detect_rig(m.names), m.names, m.positions, OPENBODY_LAYOUT)
    joints = resample_positions(np.matmul(W, m.positions), m.fps, 20.0)[:120]
    fit = fit_betas_to_clip(openbody, joints)
    rest = openbody.rest_joints(torch.tensor(fit.betas)[None])[0].double().numpy()
    res = solve_ik_calibrated(joints, rest)
    assert res.marker_error_cm <= 1.5
    assert res.raw_error_cm < 3.0
    assert res.offset_cm.max() <= MAX_OFFSET * 100 + 1e-6
    assert res.ik.rotations.shape == (len(joints), 24, 3, 3)
    # the pose is a normal body pose: its FK + transl are the joint centres the raw error measures
    from shapemove.core.geometry.torch_ops import forward_kinematics
    pos, _ = forward_kinematics(torch.tensor(res.ik.rotations).double(), torch.tensor(rest).expand(len(joints), -1, -1),
                                PARENTS)
    raw = np.linalg.norm(pos[:, :22].numpy() + res.ik.transl[:, None] - joints, axis=-1)
    assert raw.mean() * 100 == pytest.approx(res.raw_error_cm, abs=1e-3)
