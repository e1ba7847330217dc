"""Known-answer tests of the evaluation metrics on box meshes and a 'box person' body model."""
from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from shapemove.core.geometry.torch_ops import axis_angle_to_matrix
from shapemove.core.body.model import BodyModel
from shapemove.core.body.skeleton import BODY_BONES
from shapemove.core.errors import ShapeMoveError
from shapemove.core.eval import (
    MassModel, aggregate, bone_length_error_mm, bone_length_variance_mm, convex_hull_2d, distance_outside,
    dynamic_stability, evaluate_joints, evaluate_motion, format_table, mesh_motion, mpjpe_mm, penetrate,
    skate, skate_from_joints, target_bone_lengths, zmp,
)
from shapemove.core.eval.evaluate import METRIC_KEYS
from shapemove.core.eval.physics import STRICT_SKATE, foot_vertex_ids


# -- fixtures: meshes -----------------------------------------------------------------------------
def box_mesh(lo, hi, n=1):
    """Closed box surface from corner lo to hi, n x n quads per side, outward-facing triangles."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    verts, faces = [], []
    g = np.linspace(0, 1, n + 1)
    for axis in range(3):
        u, w = [a for a in range(3) if a != axis]
        natural = 1 if axis != 1 else -1          # sign of e_u x e_w along +axis
        for side in (0, 1):
            base = len(verts)
            for i in g:
                for j in g:
                    p = np.zeros(3)
                    p[axis], p[u], p[w] = side, i, j
                    verts.append(lo + p * (hi - lo))
            flip = natural != (1 if side else -1)
            for i in range(n):
                for j in range(n):
                    a = base + i * (n + 1) + j
                    b, c, d = a + n + 1, a + n + 2, a + 1
                    faces += [(a, c, b), (a, d, c)] if flip else [(a, b, c), (a, c, d)]
    uniq, inv = np.unique(np.round(np.array(verts), 9), axis=0, return_inverse=True)
    return uniq, inv.reshape(-1)[np.array(faces)]


def one_part(v):
    w = np.zeros((len(v), 24))
    w[:, 0] = 1
    return w


JOINTS = np.array([
    (0, .95, 0), (.1, .9, 0), (-.1, .9, 0), (0, .1, 0), (.1, .5, 0), (-.1, .5, 0), (0, 1.2, 0),
    (.1, .07, 0), (-.1, .07, 0), (0, 1.35, 0), (.1, .03, .1), (-.1, .03, .1), (0, 1.5, 0),
    (.07, 1.45, 0), (-.07, 1.45, 0), (0, 1.6, 0), (.13, 1.45, 0), (-.13, 1.45, 0), (.14, 1.2, 0),
    (-.14, 1.2, 0), (.14, 1.0, 0), (-.14, 1.0, 0), (.14, .9, 0), (-.14, .9, 0)])
BOXES = [  # (lo, hi, skinning joint): left foot, right foot, torso (skinned to spine1, pivot at y=0.1)
    ((.05, 0, -.05), (.15, .08, .15), 10),
    ((-.15, 0, -.05), (-.05, .08, .15), 11),
    ((-.15, .08, -.1), (.15, 1.7, .1), 3),
]


def box_body() -> BodyModel:
    """A 'box person': two foot boxes and a torso box, 24 joints regressed from box corners,
    beta 0 stretches it vertically by 5 % per unit."""
    verts, faces, labels = [], [], []
    for lo, hi, joint in BOXES:
        v, f = box_mesh(lo, hi, n=3)
        faces.append(f + sum(len(x) for x in verts))
        verts.append(v)
        labels += [joint] * len(v)
    v = np.concatenate(verts)
    w = np.zeros((len(v), 24))
    w[np.arange(len(v)), labels] = 1
    reg = np.zeros((24, len(v)))
    for j, p in enumerate(JOINTS):
        lo, hi, _ = next(b for b in BOXES if np.all(p >= b[0]) and np.all(p <= b[1]))
        t = (p - lo) / (np.asarray(hi) - lo)
        for corner in np.ndindex(2, 2, 2):
            q = np.where(corner, hi, lo)
            k = np.flatnonzero(np.all(np.abs(v - q) < 1e-9, axis=1))[0]
            reg[j, k] = np.prod(np.where(corner, t, 1 - t))
    sd = np.zeros((len(v), 3, 10))
    sd[:, 1, 0] = 0.05 * v[:, 1]
    return BodyModel(v, sd, reg, w, np.concatenate(faces), name="boxbody")


@pytest.fixture(scope="module")
def body():
    return box_body()


def still(T=20, transl=(0, 0, 0)):
    return torch.eye(3).expand(T, 24, 3, 3).clone(), torch.tensor(transl, dtype=torch.float32).expand(T, 3).clone()


# -- mass model -----------------------------------------------------------------------------------
@pytest.mark.parametrize("n", [1, 3])
def test_unit_cube_volume_and_centroid(n):
    v, f = box_mesh((0, 0, 0), (1, 1, 1), n)
    vol, cen = MassModel(f, one_part(v)).part_volumes(torch.tensor(v))
    assert vol[0, 0].item() == pytest.approx(1.0, abs=1e-12)
    assert cen[0, 0].numpy() == pytest.approx([0.5, 0.5, 0.5], abs=1e-12)
    # inward-facing triangles and a rigid motion change nothing
    R = axis_angle_to_matrix(torch.tensor([0.3, -1.1, 0.4], dtype=torch.float64)).numpy()
    moved = v @ R.T + [2.0, -1.0, 5.0]
    vol2, cen2 = MassModel(f[:, ::-1], one_part(v)).part_volumes(torch.tensor(moved))
    assert vol2[0, 0].item() == pytest.approx(1.0, abs=1e-12)
    assert cen2[0, 0].numpy() == pytest.approx(R @ [0.5, 0.5, 0.5] + [2.0, -1.0, 5.0], abs=1e-12)


def test_two_part_box_is_split_at_the_seam():
    v, f = box_mesh((0, 0, 0), (1, 2, 1), 4)      # seam at y = 1 (a grid line)
    w = np.zeros((len(v), 24))
    w[v[:, 1] < 1 - 1e-9, 0] = 1
    w[v[:, 1] > 1 + 1e-9, 5] = 1
    w[np.ix_(np.abs(v[:, 1] - 1) < 1e-9, [0, 5])] = 0.5
    vol, cen = MassModel(f, w).part_volumes(torch.tensor(v))
    assert vol[0, 0].item() == pytest.approx(1.0, abs=1e-12) and vol[0, 5].item() == pytest.approx(1.0, abs=1e-12)
    assert cen[0, 0].numpy() == pytest.approx([0.5, 0.5, 0.5], abs=1e-12)
    assert cen[0, 5].numpy() == pytest.approx([0.5, 1.5, 0.5], abs=1e-12)
    assert vol.sum().item() == pytest.approx(2.0, abs=1e-12) and torch.isnan(cen[0, 1]).all()


def test_com_of_box_body_is_the_volume_weighted_box_centre(body):
    mass = MassModel(body.faces, body.skin_weights)
    vol, _ = mass.part_volumes(body.v_template)
    sizes = [np.prod(np.subtract(hi, lo)) for lo, hi, _ in BOXES]
    centres = [np.add(lo, hi) / 2 for lo, hi, _ in BOXES]
    assert vol.sum().item() == pytest.approx(sum(sizes), rel=1e-6)     # float32 template
    expected = np.average(centres, axis=0, weights=sizes)
    assert mass.center_of_mass(body.v_template)[0].numpy() == pytest.approx(expected, abs=1e-6)
    # a symmetric single box: CoM at its centre
    v, f = box_mesh((-0.2, 0.0, -0.1), (0.2, 1.8, 0.1), 3)
    assert MassModel(f, one_part(v)).center_of_mass(torch.tensor(v))[0].numpy() == pytest.approx([0, 0.9, 0], abs=1e-12)


# -- penetrate / float / skate -------------------------------------------------------------------
def test_sunk_motion_penetrates_2cm_and_lifted_motion_floats_3cm(body):
    r = evaluate_motion(body, None, *still(transl=(0, -0.02, 0)))
    assert r["penetrate_cm"] == pytest.approx(2.0, abs=0.1) and r["n_penetrate"] == 20
    assert r["float_cm"] == 0 and r["n_float"] == 0
    r = evaluate_motion(body, None, *still(transl=(0.3, 0.03, -1.0)))
    assert r["float_cm"] == pytest.approx(3.0, abs=0.1) and r["n_float"] == 20
    assert r["penetrate_cm"] == 0
    # within the 5 mm tolerance nothing is reported
    r = evaluate_motion(body, None, *still(transl=(0, 0.004, 0)))
    assert r["float_cm"] == 0 and r["penetrate_cm"] == 0
    # only the affected frames are averaged: half the frames 2 cm down
    rot, tr = still()
    tr[:10, 1] = -0.02
    r = evaluate_motion(body, None, rot, tr)
    assert r["penetrate_cm"] == pytest.approx(2.0, abs=0.1) and r["n_penetrate"] == 10


def test_sliding_feet_skate_and_standing_feet_do_not(body):
    rot, tr = still()
    tr[:, 0] = 0.03 * torch.arange(20)                       # 3 cm per frame on the ground
    r = evaluate_motion(body, None, rot, tr)
    assert r["skate_pct"] == pytest.approx(100.0) and r["n_skate"] == 19
    assert evaluate_motion(body, None, *still())["skate_pct"] == 0.0
    assert evaluate_motion(body, None, *still(), skate_params=STRICT_SKATE)["skate_pct"] == 0.0
    # 1 cm per frame: below GMD's 0.5 m/s, caught by the strict 2.5 mm/frame setting
    tr[:, 0] = 0.01 * torch.arange(20)
    assert evaluate_motion(body, None, rot, tr)["skate_pct"] == 0.0
    assert evaluate_motion(body, None, rot, tr, skate_params=STRICT_SKATE)["skate_pct"] == pytest.approx(100.0)
    # the same slide 10 cm above the ground is not skating (no contact)
    tr[:, 1] = 0.10
    assert evaluate_motion(body, None, rot, tr, skate_params=STRICT_SKATE)["skate_pct"] == 0.0


def test_skate_one_foot_sliding_half_the_time():
    T = 21
    still_foot = np.zeros((T, 1, 3))
    moving = np.zeros((T, 1, 3))
    moving[:, 0, 2] = np.r_[np.zeros(11), 0.03 * np.arange(1, 11)]   # slides in the last 10 pairs
    s = skate([still_foot, moving], **STRICT_SKATE)
    assert s.value == pytest.approx(50.0) and s.count == 20
    # GMD's 5-pair window: the first two sliding pairs average 1.8 and 2.4 cm < 2.5 cm
    assert skate([still_foot, moving]).value == pytest.approx(40.0)
    assert skate([still_foot, moving + [0, 0.06, 0]]).value == pytest.approx(0.0)   # above 5 cm


def test_joint_fallbacks():
    j = np.tile(JOINTS[:22], (20, 1, 1))
    assert skate_from_joints(j).value == 0.0
    slid = j + np.arange(20)[:, None, None] * [0.03, 0, 0]
    assert skate_from_joints(slid).value == pytest.approx(100.0)
    r = evaluate_joints(slid - [0, 0.05, 0], sole_offsets=[0.07, 0.07, 0.03, 0.03])
    assert r["penetrate_cm"] == pytest.approx(5.0) and r["skate_pct"] == pytest.approx(100.0)
    assert math.isnan(r["dyn_stable_pct"]) and r["bone_var_mm"] == pytest.approx(0.0, abs=1e-9)


# -- bones ----------------------------------------------------------------------------------------
def test_bone_metrics_known_answers(body):
    g = torch.Generator().manual_seed(0)
    rot = axis_angle_to_matrix(0.5 * torch.randn(30, 24, 3, generator=g))
    tr = torch.randn(30, 3, generator=g)
    joints = body(None, rot, tr).joints.double()
    assert bone_length_variance_mm(joints) == pytest.approx(0.0, abs=1e-3)
    target = target_bone_lengths(body)
    assert bone_length_error_mm(joints, target) == pytest.approx(0.0, abs=1e-3)
    # every bone 10 mm longer: rebuild the tree keeping each bone's direction
    j = joints.numpy()[:, :22]
    longer = j.copy()
    for p, c in BODY_BONES:
        d = j[:, c] - j[:, p]
        longer[:, c] = longer[:, p] + d * (1 + 0.01 / np.linalg.norm(d, axis=-1, keepdims=True))
    assert bone_length_error_mm(longer, target) == pytest.approx(10.0, abs=1e-3)
    assert bone_length_variance_mm(longer) == pytest.approx(0.0, abs=1e-3)
    # one bone (neck -> head) stretched by 10 mm in half of the frames
    one = j.copy()
    d = j[:15, 15] - j[:15, 12]
    one[:15, 15] += 0.01 * d / np.linalg.norm(d, axis=-1, keepdims=True)
    assert bone_length_error_mm(one, target) == pytest.approx(10.0 / 2 / 21, abs=1e-3)
    assert bone_length_variance_mm(one) == pytest.approx(5.0 / 21, abs=1e-3)   # std of {0, 10} mm is 5
    # a taller target body: error = mean |rest length difference|
    tall = target_bone_lengths(body, torch.tensor([[1.0] + [0.0] * 9]))
    assert bone_length_error_mm(body.rest_joints()[0], tall) == pytest.approx(np.abs(tall - target).mean() * 1000)


def test_mpjpe_of_a_shifted_motion_is_50mm():
    j = np.random.default_rng(1).normal(size=(10, 22, 3))
    assert mpjpe_mm(j + [0.03, 0.04, 0], j) == pytest.approx(50.0)
    assert mpjpe_mm(j + [0.03, 0.04, 0], j, root_aligned=True) == pytest.approx(0.0, abs=1e-9)


# -- ZMP / base of support ------------------------------------------------------------------------
def test_zmp_point_mass_formula_exact_for_constant_acceleration():
    t = np.arange(10) / 20.0
    com = np.stack([0.5 * 4.0 * t ** 2, np.full(10, 1.0), 0.2 + 0.5 * -2.0 * t ** 2], axis=1)
    z = zmp(com)
    assert z[:, 0] == pytest.approx(com[:, 0] - 1.0 * 4.0 / 9.81)
    assert z[:, 2] == pytest.approx(com[:, 2] + 1.0 * 2.0 / 9.81)
    assert np.all(z[:, 1] == 0)
    falling = np.stack([np.zeros(10), 2 - 0.5 * 9.81 * t ** 2, np.zeros(10)], axis=1)
    assert np.isnan(zmp(falling)).all()


def test_hull_and_distance():
    pts = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [0.2, 0.7], [1, 0.5]])
    h = convex_hull_2d(pts)
    assert len(h) == 4 and {tuple(p) for p in h} == {(0, 0), (1, 0), (1, 1), (0, 1)}
    area2 = sum(a[0] * b[1] - a[1] * b[0] for a, b in zip(h, np.roll(h, -1, 0)))
    assert area2 == pytest.approx(2.0)                       # counter-clockwise, area 1
    assert distance_outside(h, [0.5, 0.5]) == 0 and distance_outside(h, [1, 0.3]) == 0
    assert distance_outside(h, [2, 0.5]) == pytest.approx(1.0)
    assert distance_outside(h, [2, 2]) == pytest.approx(math.sqrt(2))
    seg = convex_hull_2d([[0, 0], [1, 0], [0.5, 0]])          # collinear -> segment
    assert len(seg) == 2 and distance_outside(seg, [0.5, 0.3]) == pytest.approx(0.3)
    assert distance_outside(convex_hull_2d(np.zeros((0, 2))), [0, 0]) == math.inf


def test_static_body_is_stable_with_zmp_at_com_projection(body):
    rot, tr = still(transl=(0.4, 0, -0.3))
    m = mesh_motion(body, None, rot, tr)
    z = zmp(m["com"])
    assert z[:, [0, 2]] == pytest.approx(m["com"][:, [0, 2]], abs=1e-6)
    h = m["hulls"][0]   # the two foot soles: x in [-0.15, 0.15], z in [-0.05, 0.15], shifted
    assert h[:, 0].min() == pytest.approx(0.25) and h[:, 0].max() == pytest.approx(0.55)
    assert h[:, 1].min() == pytest.approx(-0.35) and h[:, 1].max() == pytest.approx(-0.15)
    r = evaluate_motion(body, None, rot, tr)
    assert r["dyn_stable_pct"] == 100.0 and r["zmp_out_cm"] == 0.0 and r["n_stability"] == 20


def test_swaying_torso_throws_the_zmp_out_and_flight_is_unstable(body):
    T = 40
    rot, tr = still(T)
    angle = 0.25 * torch.sin(2 * math.pi * 2.5 * torch.arange(T) / 20.0)   # 2.5 Hz sideways sway
    rot[:, 3] = axis_angle_to_matrix(torch.stack([torch.zeros(T), torch.zeros(T), angle], 1))
    r = evaluate_motion(body, None, rot, tr)
    m = mesh_motion(body, None, rot, tr)
    out = np.array([distance_outside(h, p[[0, 2]]) for h, p in zip(m["hulls"], zmp(m["com"]))])
    assert r["dyn_stable_pct"] < 50 and r["zmp_out_cm"] > 10
    assert r["zmp_out_cm"] == pytest.approx(out[out > 1e-6].mean() * 100)
    # the feet stay planted: no skating, no float
    assert r["skate_pct"] == 0.0 and r["float_cm"] == 0.0
    # a body in the air has no support: unstable as HUMOS, or left out
    rot, tr = still(transl=(0, 0.3, 0))
    assert evaluate_motion(body, None, rot, tr)["dyn_stable_pct"] == 0.0
    excl = evaluate_motion(body, None, rot, tr, no_contact="exclude")
    assert excl["n_stability"] == 0


def test_dynamic_stability_counts():
    sq = convex_hull_2d([[0, 0], [1, 0], [1, 1], [0, 1]])
    z = np.array([[0.5, 0, 0.5], [3, 0, 0.5], [1.5, 0, 0.5], [0.5, 0, 0.5]])
    s = dynamic_stability(z, [sq, sq, sq, np.zeros((0, 2))])
    assert s["dyn_stable_pct"] == pytest.approx(25.0) and s["n_stability"] == 4
    assert s["zmp_out_cm"] == pytest.approx(125.0) and s["n_zmp_out"] == 2
    assert dynamic_stability(z, [sq, sq, sq, np.zeros((0, 2))], no_contact="exclude")["dyn_stable_pct"] == pytest.approx(100 / 3)


# -- evaluate / aggregate / report ----------------------------------------------------------------
def test_evaluate_motion_keys_chunking_and_betas(body):
    rot, tr = still(T=150)
    tr[:, 0] = 0.03 * torch.arange(150)
    r = evaluate_motion(body, np.zeros(10), rot, tr)
    assert set(METRIC_KEYS) <= set(r) and r["n_frames"] == 150 and r["skate_pct"] == pytest.approx(100.0)
    # joints of a different (taller) body: bone error against the target betas
    tall = np.r_[1.0, np.zeros(9)]
    joints = body(torch.tensor(tall[None], dtype=torch.float32), rot, tr).joints[:, :22]
    r2 = evaluate_motion(body, None, rot, tr, joints=joints)
    r3 = evaluate_motion(body, None, rot, tr, joints=joints, target_betas=tall)
    assert r2["bone_err_mm"] > 10 and r3["bone_err_mm"] == pytest.approx(0.0, abs=1e-3)


def test_aggregate_is_frame_weighted_and_table_has_gt_column():
    a = {"penetrate_cm": 2.0, "n_penetrate": 10, "skate_pct": 50.0, "n_skate": 9, "bone_var_mm": 1.0,
         "n_frames": 10, "dyn_stable_pct": float("nan"), "n_stability": 0}
    b = {"penetrate_cm": 0.0, "n_penetrate": 0, "skate_pct": 0.0, "n_skate": 29, "bone_var_mm": 3.0,
         "n_frames": 30, "dyn_stable_pct": 80.0, "n_stability": 30}
    g = aggregate([a, b])
    assert g["penetrate_cm"] == pytest.approx(2.0) and g["n_penetrate"] == 10
    assert g["skate_pct"] == pytest.approx(50 * 9 / 38) and g["bone_var_mm"] == pytest.approx(2.5)
    assert g["dyn_stable_pct"] == pytest.approx(80.0) and g["clips"] == 2 and g["frames"] == 40
    text = format_table(g, ground_truth=b)
    assert "ground truth" in text and "Penetrate" in text and "2.00" in text and "80.00" in text
    with pytest.raises(ShapeMoveError):
        aggregate([])


def test_bad_input_raises_shapemove_error(body):
    rot, tr = still()
    with pytest.raises(ShapeMoveError):
        evaluate_motion(body, None, rot[:, :22], tr)
    with pytest.raises(ShapeMoveError):
        evaluate_motion(body, None, rot, tr[:5])
    with pytest.raises(ShapeMoveError):
        evaluate_motion(body, np.zeros(3), rot, tr)
    with pytest.raises(ShapeMoveError):
        mpjpe_mm(np.zeros((4, 22, 3)), np.zeros((5, 22, 3)))
    assert penetrate(np.array([0.0, 0.01])).count == 0
    with pytest.raises(ShapeMoveError):
        skate([np.full((5, 1, 3), np.nan)])
    assert len(foot_vertex_ids(body.skin_weights)["left"]) > 0


# -- the real body model --------------------------------------------------------------------------
def test_openbody_standing_still(request):
    ob = request.getfixturevalue("openbody")
    mass = MassModel(ob.faces, ob.skin_weights)
    rest = ob.rest_vertices()[0]
    vol, _ = mass.part_volumes(rest)
    assert 0.04 < vol.sum().item() < 0.12          # an adult body is ~0.06-0.08 m^3
    rot, tr = still(T=10, transl=(0, -rest[:, 1].min().item(), 0))
    r = evaluate_motion(ob, None, rot, tr)
    assert r["penetrate_cm"] == 0 and r["float_cm"] == 0 and r["skate_pct"] == 0
    assert r["bone_var_mm"] == pytest.approx(0, abs=1e-3) and r["bone_err_mm"] == pytest.approx(0, abs=1e-3)
    assert r["dyn_stable_pct"] == 100.0
