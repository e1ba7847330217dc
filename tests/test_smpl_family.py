"""SMPL-family loader: the same arrays from .npz / .pkl / chumpy .pkl, forward() equal to smplx's own
output on the same files, the 24-joint mapping of SMPL-H/X, the model factory, and clear errors."""
from __future__ import annotations

import numpy as np
import pytest
import smplx
import torch
from smplx.lbs import lbs
from synthetic_smpl import SMALL_VERTEX_IDS, write_model

from shapemove.core.body.load import clear_cache, load_body_model
from shapemove.core.body.smpl_family import SMPLFamilyBody
from shapemove.core.errors import ShapeMoveError


def _random_pose(B: int, seed: int, scale: float = 0.6):
    g = torch.Generator().manual_seed(seed)
    betas = (torch.rand(B, 10, generator=g) * 4 - 2)
    pose = torch.randn(B, 24, 3, generator=g) * scale
    transl = torch.randn(B, 3, generator=g)
    return betas, pose, transl


@pytest.fixture(scope="module")
def smpl_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("smpl")
    files = {"npz": d / "SMPL_NEUTRAL.npz", "pkl": d / "basicModel_f_lbs_10_207_0_v1.0.0.pkl",
             "chumpy": d / "basicmodel_m_lbs_10_207_0_v1.0.0.pkl"}
    arrays = write_model(files["npz"])
    write_model(files["pkl"])
    write_model(files["chumpy"], chumpy=True)
    return files, arrays


def test_npz_pkl_and_chumpy_pkl_give_the_same_model(smpl_files):
    files, arrays = smpl_files
    bodies = {k: SMPLFamilyBody.load(p) for k, p in files.items()}
    assert [b.name for b in bodies.values()] == ["smpl-neutral", "smpl-female", "smpl-male"]
    ref = bodies["npz"]
    np.testing.assert_allclose(ref.v_template.numpy(), arrays["v_template"], atol=1e-6)
    np.testing.assert_allclose(ref.shapedirs.numpy(), arrays["shapedirs"][..., :10], atol=1e-6)
    np.testing.assert_allclose(ref.joint_template.numpy(), arrays["J_regressor"] @ arrays["v_template"], atol=1e-6)
    for b in bodies.values():
        for buf in ("v_template", "shapedirs", "j_regressor", "skin_weights_t", "posedirs"):
            assert torch.equal(getattr(b, buf), getattr(ref, buf)), buf
        assert np.array_equal(b.faces, arrays["f"].astype(np.int64))


@pytest.mark.parametrize("kind", ["npz", "pkl", "chumpy"])
def test_forward_matches_smplx_smpl(smpl_files, kind):
    files, arrays = smpl_files
    body = SMPLFamilyBody.load(files[kind])
    # smplx.SMPL reads only pickles without chumpy: use the plain .pkl written from the same arrays
    ref = smplx.SMPL(model_path=str(files["pkl"]), vertex_ids=SMALL_VERTEX_IDS, num_betas=10, batch_size=4)
    betas, pose, transl = _random_pose(4, seed=1)
    out = body(betas, pose, transl)
    with torch.no_grad():
        exp = ref(betas=betas, global_orient=pose[:, 0], body_pose=pose[:, 1:].reshape(4, -1), transl=transl)
    assert out.vertices.shape == exp.vertices.shape == (4, len(arrays["v_template"]), 3)
    torch.testing.assert_close(out.vertices, exp.vertices, atol=1e-5, rtol=0)
    torch.testing.assert_close(out.joints, exp.joints[:, :24], atol=1e-5, rtol=0)
    # the pose correctives matter here (so the agreement above checks them) ...
    plain = SMPLFamilyBody.load(files[kind], pose_correctives=False)
    assert (plain(betas, pose, transl).vertices - out.vertices).abs().max() > 1e-3
    # ... and vanish in the rest pose
    rest = torch.zeros(4, 24, 3)
    torch.testing.assert_close(plain(betas, rest).vertices, body(betas, rest).vertices)


def test_forward_matches_smplx_smplh(tmp_path):
    path = tmp_path / "SMPLH_MALE.npz"
    arrays = write_model(path, family="smplh")
    body = SMPLFamilyBody.load(path)
    assert body.name == "smplh-male" and body.family == "smplh"
    ref = smplx.SMPLH(model_path=str(path), ext="npz", vertex_ids=SMALL_VERTEX_IDS, use_pca=False,
                      flat_hand_mean=True, num_betas=10, batch_size=3)
    betas, pose, transl = _random_pose(3, seed=2)
    pose[:, 22:] = 0  # the 24-joint rig keeps the fingers flat
    out = body(betas, pose, transl)
    with torch.no_grad():
        exp = ref(betas=betas, global_orient=pose[:, 0], body_pose=pose[:, 1:22].reshape(3, -1), transl=transl,
                  left_hand_pose=torch.zeros(3, 45), right_hand_pose=torch.zeros(3, 45))
    torch.testing.assert_close(out.vertices, exp.vertices, atol=1e-5, rtol=0)
    torch.testing.assert_close(out.joints[:, :22], exp.joints[:, :22], atol=1e-5, rtol=0)
    # hand joint = mean of the index/middle/pinky/ring knuckles (joints 22, 25, 28, 31)
    knuckles = (arrays["J_regressor"] @ arrays["v_template"])[[22, 25, 28, 31]].mean(0)
    np.testing.assert_allclose(body.joint_template[22].numpy(), knuckles, atol=1e-6)
    # finger weights are summed into the hand: rows still sum to one, hand group = all finger joints
    w = body.skin_weights
    np.testing.assert_allclose(w.sum(1), 1.0, atol=1e-6)
    np.testing.assert_allclose(w[:, 22], arrays["weights"][:, 22:37].sum(1), atol=1e-6)


def test_smplx_file_matches_smplx_lbs(tmp_path):
    """smplx.SMPLX needs the 10475-vertex mesh (fixed landmark ids), so compare with smplx's lbs()."""
    path = tmp_path / "smplx" / "SMPLX_FEMALE.pkl"
    path.parent.mkdir()
    arrays = write_model(path, family="smplx", chumpy=True, num_betas=20)
    body = load_body_model(tmp_path)  # the folder -> its smplx/ subfolder
    assert isinstance(body, SMPLFamilyBody) and body.name == "smplx-female"
    betas, pose, transl = _random_pose(2, seed=3)
    pose[:, 22:] = 0
    full = torch.zeros(2, 55, 3)
    full[:, :22] = pose[:, :22]
    f = lambda a: torch.as_tensor(np.asarray(a), dtype=torch.float32)  # noqa: E731
    pd = arrays["posedirs"]
    parents = torch.as_tensor(arrays["kintree_table"][0].astype(np.int64))
    parents[0] = -1
    verts, joints = lbs(betas, full.reshape(2, -1), f(arrays["v_template"]), f(arrays["shapedirs"][..., :10]),
                        f(pd.reshape(-1, pd.shape[-1]).T), f(arrays["J_regressor"]), parents, f(arrays["weights"]))
    out = body(betas, pose, transl)
    torch.testing.assert_close(out.vertices, verts + transl[:, None], atol=1e-5, rtol=0)
    torch.testing.assert_close(out.joints[:, :22], joints[:, :22] + transl[:, None], atol=1e-5, rtol=0)
    # jaw and eye weights go to the head
    np.testing.assert_allclose(body.skin_weights[:, 15], arrays["weights"][:, [15, 22, 23, 24]].sum(1), atol=1e-6)


def test_npz_with_sparse_regressor_object_is_refused(tmp_path):
    """A hand-converted npz holding J_regressor as a pickled scipy.sparse object is refused with a
    sentence (pickles inside an .npz are never loaded: see tests/test_hostile_body_files.py)."""
    import scipy.sparse

    ok = write_model(tmp_path / "SMPL_MALE.npz")
    (tmp_path / "sparse").mkdir()
    write_model(tmp_path / "sparse" / "SMPL_MALE.npz",
                J_regressor=np.array(scipy.sparse.csr_matrix(ok["J_regressor"]), dtype=object))
    with pytest.raises(ShapeMoveError, match="J_regressor is a pickled Python object.*dense"):
        SMPLFamilyBody.load(tmp_path / "sparse" / "SMPL_MALE.npz")


def test_factory_caches_and_resolves(smpl_files, tmp_path):
    files, _ = smpl_files
    clear_cache()
    a = load_body_model(files["npz"])
    assert load_body_model(str(files["npz"])) is a
    assert load_body_model(files["pkl"]) is not a
    with pytest.raises(ShapeMoveError, match="openbody"):
        load_body_model("smpl-neutral-but-not-a-path")
    # a folder with several models: pick by gender, else ask for the file
    with pytest.raises(ShapeMoveError, match="several body models"):
        SMPLFamilyBody.load(files["npz"].parent, gender="male_and_female")
    assert SMPLFamilyBody.load(files["npz"].parent, gender="female").name == "smpl-female"
    with pytest.raises(ShapeMoveError, match="no .npz/.pkl body model"):
        load_body_model(tmp_path)


def test_factory_openbody():
    from shapemove.core.body.openbody import OpenBody

    body = load_body_model()
    assert isinstance(body, OpenBody) and load_body_model("openbody") is body


@pytest.mark.parametrize("make, match", [
    (lambda d: d / "SMPL_NEUTRAL.npz", "not found.*smpl.is.tue.mpg.de.*--body-model"),
    (lambda d: write_model(d / "m.npz") and (d / "m.npz").rename(d / "m.obj") or d / "m.obj", "expected .npz or .pkl"),
    (lambda d: write_model(d / "m.npz", drop=("J_regressor", "f")) and d / "m.npz", "lacks key.*J_regressor, f"),
    (lambda d: write_model(d / "m.pkl", weights=np.ones((5, 24))) and d / "m.pkl", r"weights should be \(376,24\)"),
    (lambda d: write_model(d / "m.npz", shapedirs=np.ones((376, 3))) and d / "m.npz", "shapedirs should be"),
    (lambda d: write_model(d / "m.npz", posedirs=np.ones((376, 3, 9))) and d / "m.npz", "posedirs should be"),
    (lambda d: write_model(d / "m.npz", f=np.array([[0, 1, 9999]])) and d / "m.npz", "vertex indices below 376"),
    (lambda d: write_model(d / "m.npz", J_regressor=np.ones((16, 376))) and d / "m.npz", "16 joints.*MANO"),
    (lambda d: (d / "m.npz").write_bytes(b"not a zip") and d / "m.npz", "could not read body model file"),
    (lambda d: (d / "m.pkl").write_bytes(b"\x80\x02cos\nsystem\nq\x00.") and d / "m.pkl", "could not read.*os.system"),
])
def test_clear_errors(tmp_path, make, match):
    path = make(tmp_path)
    with pytest.raises(ShapeMoveError, match=match):
        SMPLFamilyBody.load(path)


def test_wrong_tree_is_rejected(tmp_path):
    a = write_model(tmp_path / "x.npz")
    kt = a["kintree_table"].copy()
    kt[0, 4] = 2  # left knee under the right hip
    write_model(tmp_path / "x.npz", kintree_table=kt)
    with pytest.raises(ShapeMoveError, match="not the SMPL joint tree"):
        SMPLFamilyBody.load(tmp_path / "x.npz")
