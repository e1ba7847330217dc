"""OpenBody asset: layout of the mean body, linear shape space, sliders, skinning, errors."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from shapemove.core.geometry.torch_ops import axis_angle_to_matrix
from shapemove.core.body.measure import measure
from shapemove.core.body.openbody import OpenBody
from shapemove.core.body.skeleton import JOINT_INDEX as JI
from shapemove.core.body.skeleton import JOINT_NAMES
from shapemove.core.errors import ShapeMoveError


def test_mean_body_is_an_adult_in_t_pose(openbody):
    assert openbody.name == "openbody-v1"
    assert openbody.num_vertices > 10000 and openbody.faces.shape[1] == 3
    assert openbody.faces.min() == 0 and openbody.faces.max() == openbody.num_vertices - 1
    v = openbody.rest_vertices()[0].numpy()
    j = openbody.rest_joints()[0].numpy()
    assert abs(v[:, 1].min()) < 1e-4  # feet on the floor
    assert 1.65 < v[:, 1].max() < 1.80
    y = {n: j[JI[n], 1] for n in JOINT_NAMES}
    assert y["head"] > y["neck"] > y["spine3"] > y["spine2"] > y["spine1"] > y["pelvis"]
    for s in ("left", "right"):
        assert y[f"{s}_hip"] > y[f"{s}_knee"] > y[f"{s}_ankle"] > 0
        assert y[f"{s}_ankle"] < 0.15 and y[f"{s}_foot"] < 0.06
        # T-pose: the arm is horizontal, the wrist far out
        for part in ("elbow", "wrist", "hand"):
            assert abs(y[f"{s}_{part}"] - y[f"{s}_shoulder"]) < 0.03
        sign = 1 if s == "left" else -1
        assert sign * j[JI[f"{s}_wrist"], 0] > 0.55
        assert sign * j[JI[f"{s}_hand"], 0] > sign * j[JI[f"{s}_wrist"], 0] > sign * j[JI[f"{s}_elbow"], 0]
        for n in JOINT_NAMES:
            if n.startswith(s):
                assert sign * j[JI[n], 0] > 0.03, n
    # toes point forward (+Z): the foot joint is in front of the ankle
    assert j[JI["left_foot"], 2] > j[JI["left_ankle"], 2] + 0.05


def test_left_right_mirror_symmetry(openbody):
    j = openbody.rest_joints(torch.randn(1, 10, generator=torch.Generator().manual_seed(1)))[0].numpy()
    for n in JOINT_NAMES:
        if n.startswith("left_"):
            l, r = j[JI[n]], j[JI[n.replace("left_", "right_")]]
            np.testing.assert_allclose(l * [-1, 1, 1], r, atol=2e-3, err_msg=n)


def test_each_beta_changes_the_mesh_linearly(openbody):
    base = torch.zeros(1, 10)
    v0, j0 = openbody.rest_vertices(base)[0], openbody.rest_joints(base)[0]
    for k in range(10):
        e = torch.zeros(1, 10)
        e[0, k] = 1.0
        d1 = openbody.rest_vertices(e)[0] - v0
        d2 = openbody.rest_vertices(2 * e)[0] - v0
        assert torch.allclose(d2, 2 * d1, atol=1e-5)
        # one standard deviation moves the body by millimetres to decimetres, not zero, not metres
        assert 0.003 < d1.norm(dim=-1).max() < 0.3, k
        dj = openbody.rest_joints(e)[0] - j0
        assert torch.allclose(openbody.rest_joints(-e)[0] - j0, -dj, atol=1e-5)
    # the first beta carries most of the variance (body size)
    assert openbody.explained_variance[0] > openbody.explained_variance[1:].max()


def test_joint_regressor_is_affine(openbody):
    J = openbody.j_regressor
    assert torch.allclose(J.sum(1), torch.ones(24), atol=1e-4)
    v = openbody.rest_vertices()[0]
    shift = torch.tensor([0.3, -0.2, 1.5])
    assert torch.allclose(J @ (v + shift), J @ v + shift, atol=1e-4)


def test_skin_weights_are_a_partition(openbody):
    w = openbody.skin_weights
    assert w.shape == (openbody.num_vertices, 24)
    assert w.min() >= 0
    np.testing.assert_allclose(w.sum(1), 1.0, atol=1e-5)
    # every joint is the main influence somewhere on the surface
    dominant = np.bincount(w.argmax(1), minlength=24)
    assert (dominant >= 20).all(), dict(zip(JOINT_NAMES, dominant))


def test_height_slider_is_monotonic(openbody):
    lo, hi = openbody.phenotype_ranges[openbody.phenotype_names.index("height")]
    values = np.linspace(lo, hi, 5)
    betas = np.stack([openbody.betas_from_phenotype({"height": h}) for h in values])
    heights = measure(openbody, betas)["height_cm"]
    assert np.all(np.diff(heights) > 1.0), heights
    assert heights[-1] - heights[0] > 15


def test_gender_and_weight_sliders_act_as_named(openbody):
    m = measure(openbody, np.stack([openbody.betas_from_phenotype(p) for p in
                                    ({"gender": 0.0}, {"gender": 1.0}, {"weight": 0.2}, {"weight": 0.8})]))
    assert m["height_cm"][0] > m["height_cm"][1] + 5  # 0 = male, taller on average
    assert m["waist_cm"][3] > m["waist_cm"][2] + 5


def test_betas_from_phenotype_api(openbody):
    assert openbody.phenotype_names == ["gender", "age", "muscle", "weight", "height", "proportions"]
    assert openbody.phenotype_ranges.shape == (6, 2)
    assert np.all(openbody.phenotype_ranges[:, 0] < openbody.phenotype_ranges[:, 1])
    # the sample mean phenotype is the mean body
    np.testing.assert_allclose(openbody.betas_from_phenotype({}), 0, atol=1e-4)
    p = {"gender": 0.2, "age": 40, "muscle": 0.6, "weight": 0.4, "height": 0.5, "proportions": 0.5}
    a = openbody.betas_from_phenotype(p)
    b = openbody.betas_from_phenotype(np.array(list(p.values())))
    assert a.shape == (10,)
    np.testing.assert_allclose(a, b, atol=1e-6)
    batch = openbody.betas_from_phenotype(np.stack([list(p.values())] * 3))
    assert batch.shape == (3, 10)
    with pytest.raises(ShapeMoveError, match="unknown phenotype"):
        openbody.betas_from_phenotype({"shoe_size": 1})
    with pytest.raises(ShapeMoveError, match="6 values"):
        openbody.betas_from_phenotype([0.5, 0.5])


def test_forward_identity_is_rest_pose(openbody):
    betas = torch.randn(2, 10, generator=torch.Generator().manual_seed(0))
    out = openbody(betas, torch.zeros(2, 24, 3))
    assert torch.allclose(out.vertices, openbody.rest_vertices(betas), atol=1e-5)
    assert torch.allclose(out.joints, openbody.rest_joints(betas), atol=1e-5)


def test_bending_the_elbow_moves_only_forearm_and_hand(openbody):
    rot = torch.zeros(1, 24, 3)
    rot[0, JI["left_elbow"]] = torch.tensor([0.0, -np.pi / 2, 0.0])  # forearm swings to +Z
    rest = openbody.rest_vertices()[0]
    out = openbody(None, rot)
    moved = (out.vertices[0] - rest).norm(dim=-1)
    w = openbody.skin_weights
    driven = w[:, [JI["left_elbow"], JI["left_wrist"], JI["left_hand"]]].sum(1)
    assert moved[torch.as_tensor(driven == 0)].max() < 1e-5
    # vertices carried entirely by the forearm chain turn rigidly about the elbow's vertical axis:
    # a 90 degree turn moves a point by sqrt(2) times its distance from that axis
    rigid = torch.as_tensor(driven > 0.999)
    offset = rest[rigid] - openbody.rest_joints()[0, JI["left_elbow"]]
    r_perp = offset[:, [0, 2]].norm(dim=-1)
    assert rigid.sum() > 500 and r_perp.max() > 0.3
    assert torch.allclose(moved[rigid], np.sqrt(2) * r_perp, atol=2e-3)
    j_rest, j = openbody.rest_joints()[0], out.joints[0]
    assert torch.allclose(j[: JI["left_elbow"] + 1], j_rest[: JI["left_elbow"] + 1], atol=1e-6)
    # the wrist went from +X of the elbow to +Z of it, at the same distance
    R = axis_angle_to_matrix(rot[0, JI["left_elbow"]])
    expected = j_rest[JI["left_elbow"]] + R @ (j_rest[JI["left_wrist"]] - j_rest[JI["left_elbow"]])
    assert torch.allclose(j[JI["left_wrist"]], expected, atol=1e-5)
    assert j[JI["left_wrist"], 2] - j[JI["left_elbow"], 2] > 0.2


def test_missing_or_corrupt_asset_says_how_to_rebuild(tmp_path):
    with pytest.raises(ShapeMoveError, match="build_openbody.py"):
        OpenBody.load(tmp_path / "nope.npz")
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a zip file")
    with pytest.raises(ShapeMoveError, match="build_openbody.py"):
        OpenBody.load(bad)
    partial = tmp_path / "partial.npz"
    np.savez(partial, v_template=np.zeros((3, 3)))
    with pytest.raises(ShapeMoveError, match="lacks"):
        OpenBody.load(partial)


def test_cli_body_info(capsys):
    from shapemove.cli import main

    assert main(["body", "info"]) == 0
    out = capsys.readouterr().out
    assert "openbody-v1" in out and "left_wrist" in out and "height_cm" in out
    assert "CC0" in out and "gender" in out
    assert main(["body", "info", "--model", "/no/such/model.npz"]) == 2
