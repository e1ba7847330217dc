"""core.geometry: numpy rotations and FK checked against scipy and hand-derived values, and the
torch twins checked against the numpy functions (same names, same numbers)."""
from __future__ import annotations

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from shapemove.core.body.skeleton import PARENTS
from shapemove.core.geometry import fk, rotations as R, torch_ops


def _rotvecs(n, seed=0, scale=1.5):
    return np.random.default_rng(seed).normal(0, scale, (n, 3))


def test_axis_angle_and_quaternion_agree_with_scipy():
    aa = _rotvecs(200, seed=1)
    aa[0] = 0
    aa[1] = [np.pi, 0, 0]
    ref = Rotation.from_rotvec(aa).as_matrix()
    np.testing.assert_allclose(R.axis_angle_to_matrix(aa), ref, atol=1e-12)
    q = R.matrix_to_quaternion(ref)
    xyzw = Rotation.from_matrix(ref).as_quat()
    ref_q = np.concatenate([xyzw[:, 3:], xyzw[:, :3]], -1)
    ref_q *= np.where(ref_q[:, :1] < 0, -1, 1)
    np.testing.assert_allclose(np.abs((q * ref_q).sum(-1)), 1, atol=1e-12)
    np.testing.assert_allclose(R.quaternion_to_matrix(q), ref, atol=1e-12)
    # axis-angle back: same rotation, angle in [0, pi]
    back = R.matrix_to_axis_angle(ref)
    assert (np.linalg.norm(back, axis=-1) <= np.pi + 1e-9).all()
    np.testing.assert_allclose(R.axis_angle_to_matrix(back), ref, atol=1e-9)
    small = np.array([[1e-9, -2e-9, 3e-9]])
    np.testing.assert_allclose(R.matrix_to_axis_angle(R.axis_angle_to_matrix(small)), small, atol=1e-15)


def test_euler_yaw_and_6d():
    ang = np.random.default_rng(2).uniform(-3, 3, (50, 3))
    np.testing.assert_allclose(R.euler_matrix("zxy", ang), Rotation.from_euler("ZXY", ang).as_matrix(), atol=1e-12)
    np.testing.assert_allclose(R.yaw_matrix(np.pi / 2) @ [0, 0, 1], [1, 0, 0], atol=1e-15)
    rot = R.axis_angle_to_matrix(_rotvecs(30, seed=3))
    d6 = R.matrix_to_rot6d(rot)
    np.testing.assert_array_equal(d6[:, :3], rot[:, :, 0])
    np.testing.assert_allclose(R.rot6d_to_matrix(d6), rot, atol=1e-12)
    # Gram-Schmidt of a skewed pair keeps the first column's direction
    m = R.rot6d_to_matrix(np.array([2.0, 0, 0, 1.0, 1.0, 0]))
    np.testing.assert_allclose(m, np.eye(3), atol=1e-12)


def test_rotation_between_is_the_shortest_arc():
    rng = np.random.default_rng(4)
    u, v = rng.normal(size=(100, 3)), rng.normal(size=(100, 3))
    u[0], v[0] = [0, 0, 2.0], [0, 0, -1.0]  # opposite: a half turn
    rot = R.rotation_between(u, v)
    un = u / np.linalg.norm(u, axis=-1, keepdims=True)
    vn = v / np.linalg.norm(v, axis=-1, keepdims=True)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", rot, un), vn, atol=1e-12)
    angle = np.linalg.norm(R.matrix_to_axis_angle(rot), axis=-1)
    np.testing.assert_allclose(angle, np.arccos(np.clip((un * vn).sum(-1), -1, 1)), atol=1e-7)


def test_slerp_constant_speed_and_shortest_way():
    q0 = R.matrix_to_quaternion(np.eye(3))
    q1 = R.matrix_to_quaternion(R.axis_rotation("y", 1.2))
    w = np.linspace(0, 1, 7)
    out = R.slerp(np.broadcast_to(q0, (7, 4)), np.broadcast_to(-q1, (7, 4)), w)  # -q1: same rotation
    np.testing.assert_allclose(R.quaternion_to_matrix(out), R.axis_rotation("y", 1.2 * w), atol=1e-12)
    cont = R.make_continuous(np.stack([q1, -q1, q1]))
    assert (np.sum(cont[1:] * cont[:-1], -1) > 0).all()


def test_forward_kinematics_by_hand_and_offsets_round_trip():
    parents = [-1, 0, 1]
    rest = np.array([[0.0, 1, 0], [0, 2, 0], [0, 3, 0]])
    rot = np.broadcast_to(np.eye(3), (3, 3, 3)).copy()
    rot[1] = R.axis_rotation("z", np.pi / 2)  # the middle joint turns the last bone to -X
    pos, world = fk.forward_kinematics(rot, rest, parents)
    np.testing.assert_allclose(pos, [[0, 1, 0], [0, 2, 0], [-1, 2, 0]], atol=1e-12)
    np.testing.assert_allclose(world[2], rot[1], atol=1e-12)
    np.testing.assert_allclose(fk.joints_from_offsets(fk.bone_offsets(rest, parents), parents), rest)
    # a root rest position per frame moves the whole skeleton
    rest_t = rest[None] + np.array([[0.0, 0, 0], [5, 0, 0]])[:, None]
    pos_t, _ = fk.forward_kinematics(rot, rest_t, parents)
    np.testing.assert_allclose(pos_t[1] - pos_t[0], np.tile([5.0, 0, 0], (3, 1)), atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1])
def test_torch_twins_match_numpy(seed):
    aa = _rotvecs(24 * 4, seed=seed).reshape(4, 24, 3)
    aa[0, 0] = 0
    rot_t = torch_ops.axis_angle_to_matrix(torch.as_tensor(aa))
    np.testing.assert_allclose(rot_t.numpy(), R.axis_angle_to_matrix(aa), atol=1e-12)
    rest = np.random.default_rng(seed).normal(size=(24, 3))
    pos_np, world_np = fk.forward_kinematics(rot_t.numpy(), rest, PARENTS)
    pos_t, world_t = torch_ops.forward_kinematics(rot_t, torch.as_tensor(rest), PARENTS)
    np.testing.assert_allclose(pos_t.numpy(), pos_np, atol=1e-12)
    np.testing.assert_allclose(world_t.numpy(), world_np, atol=1e-12)
    # gradients flow through the torch FK and are finite at zero rotation
    x = torch.zeros(1, 24, 3, dtype=torch.float64, requires_grad=True)
    p, _ = torch_ops.forward_kinematics(torch_ops.axis_angle_to_matrix(x), torch.as_tensor(rest), PARENTS)
    p[0, 20].sum().backward()
    assert torch.isfinite(x.grad).all() and x.grad[0, 0].abs().sum() > 0


def test_torch_shortest_arc_frame_and_offset_fk_match_numpy():
    rng = np.random.default_rng(7)
    u, v = rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    u[0], v[0] = [0, 0, 2.0], [0, 0, -1.0]   # opposite: a half turn
    u[1], v[1] = [1.0, 1, 1], [3.0, 3, 3]     # parallel: identity; the frame needs its fallback
    rot_t = torch_ops.rotation_between(torch.as_tensor(u), torch.as_tensor(v)).numpy()
    vn = v / np.linalg.norm(v, axis=-1, keepdims=True)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", rot_t, u / np.linalg.norm(u, axis=-1, keepdims=True)), vn, atol=1e-9)
    np.testing.assert_allclose(rot_t[1:], R.rotation_between(u, v)[1:], atol=1e-9)  # half turns: any axis
    f_np = R.orthonormal_frame(u, v)
    np.testing.assert_allclose(torch_ops.orthonormal_frame(torch.as_tensor(u), torch.as_tensor(v)).numpy(), f_np, atol=1e-12)
    np.testing.assert_allclose(np.einsum("nji,njk->nik", f_np, f_np), np.broadcast_to(np.eye(3), (50, 3, 3)), atol=1e-12)
    assert np.allclose(np.linalg.det(f_np), 1.0) and np.allclose(f_np[..., 0], u / np.linalg.norm(u, axis=-1, keepdims=True))
    # FK from bone offsets + a root translation == FK of the rest moved by it, on the first 22 joints
    rest = rng.normal(size=(24, 3))
    rot = R.axis_angle_to_matrix(_rotvecs(3 * 24, seed=7).reshape(3, 24, 3))
    transl = rng.normal(size=(3, 3))
    pos, world = torch_ops.forward_kinematics_offsets(torch.as_tensor(rot[:, :22]), torch.as_tensor(fk.bone_offsets(rest, PARENTS)),
                                                      PARENTS, torch.as_tensor(transl))
    pos_np, world_np = fk.forward_kinematics(rot, rest, PARENTS)
    np.testing.assert_allclose(pos.numpy(), pos_np[:, :22] + transl[:, None], atol=1e-12)
    np.testing.assert_allclose(world.numpy(), world_np[:, :22], atol=1e-12)
