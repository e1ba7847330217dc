"""Pure maths of the Blender side (no bpy): axes, bone layout, pose conversion, shape keys,
motion files, the capsule body and the extension zip."""
from __future__ import annotations

import zipfile

import numpy as np
import pytest
import torch

from shapemove.core.geometry.rotations import make_continuous, matrix_to_quaternion, quaternion_to_matrix
from shapemove.core.geometry.torch_ops import axis_angle_to_matrix, forward_kinematics
from shapemove.core.body.skeleton import JOINT_NAMES, PARENTS
from shapemove.core.errors import ShapeMoveError
from shapemove.core.scene.axes import Y_UP_TO_Z_UP, points_to_y_up, points_to_z_up, rotations_to_z_up
from shapemove.core.scene.bones import bone_layout, bone_matrix, main_children, roll_for_z_axis
from shapemove.core.scene.capsule_body import REST_JOINTS, capsule_body
from shapemove.core.scene.motion_file import load_motion, make_motion, save_motion
from shapemove.core.scene.pose import pose_bone_quaternions, rebase_quaternions, root_locations
from shapemove.core.scene.rig_data import motion_channels_z_up, rig_data


def _random_rotations(n, seed=0, scale=1.5):
    aa = torch.as_tensor(np.random.default_rng(seed).normal(0, scale, (n, 3)))
    return axis_angle_to_matrix(aa).numpy()


def test_axes_are_a_proper_rotation_with_the_documented_directions():
    assert np.allclose(Y_UP_TO_Z_UP @ Y_UP_TO_Z_UP.T, np.eye(3)) and np.isclose(np.linalg.det(Y_UP_TO_Z_UP), 1)
    assert np.allclose(points_to_z_up([0, 1, 0]), [0, 0, 1])    # up stays up
    assert np.allclose(points_to_z_up([0, 0, 1]), [0, -1, 0])   # facing +Z -> facing Blender's -Y (front view)
    assert np.allclose(points_to_z_up([1, 0, 0]), [1, 0, 0])    # left stays at +X
    p = np.random.default_rng(1).normal(size=(5, 3))
    r = _random_rotations(5)
    assert np.allclose(points_to_y_up(points_to_z_up(p)), p)
    assert np.allclose(np.einsum("nij,nj->ni", rotations_to_z_up(r), points_to_z_up(p)),
                       points_to_z_up(np.einsum("nij,nj->ni", r, p)))


def test_bone_matrix_follows_blender_conventions():
    # Blender: a bone along +Y with roll 0 has the identity rest orientation; along +Z it is
    # a +90 degree turn about X (Y->Z, Z->-Y); roll turns X/Z about the bone's Y axis.
    assert np.allclose(bone_matrix([[0, 1, 0]], [0.0])[0], np.eye(3))
    assert np.allclose(bone_matrix([[0, 0, 2]], [0.0])[0], [[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    assert np.allclose(bone_matrix([[0, -1, 0]], [0.0])[0], np.diag([-1, -1, 1]))  # the singular case
    v = np.random.default_rng(2).normal(size=(50, 3))
    rolls = np.random.default_rng(3).uniform(-3, 3, 50)
    m = bone_matrix(v, rolls)
    assert np.allclose(m @ np.swapaxes(m, 1, 2), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(m), 1)
    assert np.allclose(m[:, :, 1], v / np.linalg.norm(v, axis=1, keepdims=True))
    m0 = bone_matrix(v, np.zeros(50))
    twist = np.swapaxes(m0, 1, 2) @ m  # a rotation about local Y by the roll
    assert np.allclose(np.arctan2(twist[:, 0, 2], twist[:, 0, 0]), rolls)


def test_roll_turns_z_axis_to_the_target():
    rng = np.random.default_rng(4)
    v, t = rng.normal(size=(40, 3)), rng.normal(size=(40, 3))
    z = bone_matrix(v, roll_for_z_axis(v, t))[:, :, 2]
    y = v / np.linalg.norm(v, axis=1, keepdims=True)
    t_perp = t - (t * y).sum(1, keepdims=True) * y
    # the best reachable Z is the target's component perpendicular to the bone
    assert np.allclose(z, t_perp / np.linalg.norm(t_perp, axis=1, keepdims=True), atol=1e-9)


def test_bone_layout_on_the_capsule_skeleton():
    joints = points_to_z_up(REST_JOINTS)
    kids = main_children(joints)
    assert kids[0] == JOINT_NAMES.index("spine1") and kids[9] == JOINT_NAMES.index("neck")
    assert kids[JOINT_NAMES.index("head")] is None
    lay = bone_layout(joints)
    assert np.allclose(lay.heads, joints)
    assert np.allclose(lay.tails[JOINT_NAMES.index("left_knee")], joints[JOINT_NAMES.index("left_ankle")])
    # leaf bones continue their parent: the left hand points along +X like the forearm
    hand = JOINT_NAMES.index("left_hand")
    d = lay.tails[hand] - lay.heads[hand]
    assert d[0] > 0 and abs(d[1]) < 1e-9 and np.isclose(np.linalg.norm(d), 0.04)
    # the thigh's Z axis points to the body's front (-Y in Blender axes)
    assert lay.matrices[JOINT_NAMES.index("left_hip"), 1, 2] < -0.99


def _blender_pose_fk(rest_heads, rest_mats, quats, root_loc, parents):
    """Blender's pose evaluation for unconnected bones: pose(j) = pose(p) rest(p)^-1 rest(j) basis(j)."""
    J = len(parents)
    rest = np.tile(np.eye(4), (J, 1, 1))
    rest[:, :3, :3], rest[:, :3, 3] = rest_mats, rest_heads
    pose = np.zeros_like(rest)
    for j in range(J):
        basis = np.eye(4)
        basis[:3, :3] = quaternion_to_matrix(quats[j])
        if j == 0:
            basis[:3, 3] = root_loc
            pose[j] = rest[j] @ basis
        else:
            p = parents[j]
            pose[j] = pose[p] @ np.linalg.inv(rest[p]) @ rest[j] @ basis
    return pose


def test_pose_bone_quaternions_reproduce_smpl_forward_kinematics():
    body = capsule_body()
    betas = np.array([1.0, -0.5, 0.3, 0, 0.5, 0, 0, 0, 0, 0.2])
    rng = np.random.default_rng(5)
    poses = rng.normal(0, 0.6, (3, 24, 3))
    transl = rng.normal(0, 0.3, (3, 3))
    data = rig_data(body, betas)
    rot, tr = motion_channels_z_up(poses, transl)
    quats = pose_bone_quaternions(rot, data.bones.matrices)
    locs = root_locations(tr, data.bones.matrices[0])
    ref = body.forward(torch.tensor(betas, dtype=torch.float32)[None], torch.tensor(poses, dtype=torch.float32),
                       torch.tensor(transl, dtype=torch.float32))
    for t in range(3):
        pose = _blender_pose_fk(data.bones.heads, data.bones.matrices, quats[t], locs[t], PARENTS)
        assert np.abs(pose[:, :3, 3] - points_to_z_up(ref.joints[t].numpy())).max() < 1e-5
        # the skinning transforms agree too: pose . rest^-1 moves rest points like SMPL's LBS
        _, world = forward_kinematics(torch.tensor(rot[t:t + 1]), torch.tensor(data.bones.heads)[None], PARENTS)
        assert np.allclose(pose[:, :3, :3], world[0].numpy() @ data.bones.matrices, atol=1e-9)


def test_quaternion_round_trip_and_continuity():
    r = _random_rotations(200, seed=6, scale=2.0)
    r[0] = np.diag([1.0, -1.0, -1.0])  # 180 degrees about X: w = 0
    q = matrix_to_quaternion(r)
    assert np.allclose(np.linalg.norm(q, axis=1), 1) and (q[:, 0] >= 0).all()
    assert np.allclose(quaternion_to_matrix(q), r, atol=1e-10)
    seq = np.stack([q[5], -q[6], q[7]])[:, None]
    cont = make_continuous(seq)
    assert (np.sum(cont[1:] * cont[:-1], -1) >= 0).all()
    assert np.allclose(quaternion_to_matrix(cont), quaternion_to_matrix(seq))


def test_rebase_keeps_the_armature_space_rotation():
    old, new = _random_rotations(2, seed=7)
    q = matrix_to_quaternion(_random_rotations(10, seed=8))
    q2 = rebase_quaternions(q, old, new)
    assert np.allclose(new @ quaternion_to_matrix(q2) @ new.T, old @ quaternion_to_matrix(q) @ old.T, atol=1e-10)


def test_shape_keys_sum_to_the_body_models_rest_shape():
    body = capsule_body()
    betas = np.random.default_rng(9).normal(0, 1, 10)
    data = rig_data(body, betas)
    mixed = data.v_template + ((data.key_coords - data.v_template[None]) * betas[:, None, None]).sum(0)
    ref = points_to_z_up(body.rest_vertices(torch.tensor(betas, dtype=torch.float32))[0].numpy())
    assert np.abs(mixed - ref).max() < 1e-5
    assert np.abs(data.bones.heads - points_to_z_up(body.rest_joints(torch.tensor(betas, dtype=torch.float32))[0].numpy())).max() < 1e-5


def test_capsule_body_regresses_its_joints_and_beta0_is_height():
    body = capsule_body()
    assert np.abs(body.rest_joints()[0].numpy() - REST_JOINTS).max() < 1e-6
    b = torch.zeros(1, 10)
    b[0, 0] = 1.0
    tall = body.rest_joints(b)[0].numpy()
    assert np.allclose(tall[:, 1], REST_JOINTS[:, 1] * 1.06, atol=1e-6)  # +6 % height per unit
    assert np.allclose(body.skin_weights.sum(1), 1)


def test_motion_file_round_trip_and_errors(tmp_path):
    body = capsule_body()
    poses = np.random.default_rng(10).normal(0, 0.3, (4, 24, 3))
    transl = np.zeros((4, 3))
    m = make_motion(body, poses, transl, np.ones(10) * 0.5, fps=20, prompt="a person waves")
    path = save_motion(tmp_path / "m.npz", m)
    back = load_motion(path)
    assert back.body_model == "capsule-v1" and back.prompt == "a person waves" and back.fps == 20
    assert np.allclose(back.poses, poses, atol=1e-6) and back.joints.shape == (4, 22, 3)
    # joints of frame 0 with zero root offset: FK of the shaped rest skeleton
    ref = body.forward(torch.full((1, 10), 0.5), torch.tensor(poses[:1], dtype=torch.float32)).joints[0, :22]
    assert np.allclose(back.joints[0], ref.numpy(), atol=1e-5)
    arrays = dict(np.load(path))
    del arrays["transl"]
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(ShapeMoveError, match="transl"):
        load_motion(tmp_path / "bad.npz")
    arrays["transl"] = np.zeros((3, 3))
    np.savez(tmp_path / "bad2.npz", **arrays)
    with pytest.raises(ShapeMoveError, match="transl must be"):
        load_motion(tmp_path / "bad2.npz")
    with pytest.raises(ShapeMoveError, match="not found"):
        load_motion(tmp_path / "missing.npz")


def test_extension_zip_layout(tmp_path):
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("build_extension", root / "tools" / "build_extension.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.excluded("tests", True, ["/tests/"]) and not mod.excluded("core/tests", True, ["/tests/"])
    assert mod.excluded("core/body/__pycache__", True, ["__pycache__/"])
    assert not mod.excluded("__pycache__", False, ["__pycache__/"])  # a trailing / means folders only
    assert mod.excluded("x.egg-info", True, ["*.egg-info/"])
    zip_path = mod.build(tmp_path)
    with zipfile.ZipFile(zip_path) as zf:
        names = zf.namelist()
    assert zip_path.name == "shapemove-0.1.0.zip"
    assert "blender_manifest.toml" in names and "__init__.py" in names
    assert "shapemove_addon/keyframes.py" in names and "core/scene/pose.py" in names
    assert not [n for n in names if n.startswith(("tests/", "tools/", "bench/", ".git/", ".venv/", ".cache/"))]
    assert not [n for n in names if "__pycache__" in n or n.endswith(".pyc")]
