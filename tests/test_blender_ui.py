"""The ShapeMove panels and operators inside real Blender (bpy module), the numpy body view used
there without torch, and the worker ops behind the panels.

The Blender part is pytest tests in tests/in_blender/test_ui.py and test_ui_models.py, run in
their own process (BLENDER_USER_RESOURCES must be set before bpy is imported, torch must start
unimportable); each is reported here as one test with its own assertion message.
"""
from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import blender_inside
import numpy as np
import pytest
from conftest import need_module
from tiny_models import tiny_bundle  # noqa: F401  (session fixture)

from shapemove.core.body.body_arrays import load_body_arrays, load_smpl_arrays
from shapemove.core.errors import ShapeMoveError
from shapemove.core.scene.motion_file import make_motion, save_motion

ROOT = Path(__file__).resolve().parents[1]
FRAMES = 12
SHAPE_TEXT = "a person standing 185 cm tall"


def _motion(body, betas, seed, tokens=None):
    rng = np.random.default_rng(seed)
    t = np.arange(FRAMES)[:, None, None]
    poses = rng.normal(0, 0.3, (1, 24, 3)) * np.sin(0.3 * t + rng.uniform(0, 6, (1, 24, 3)))
    transl = np.stack([0.01 * np.arange(FRAMES), np.zeros(FRAMES), 0.03 * np.arange(FRAMES)], -1)
    extra = {} if tokens is None else {"tokens": np.asarray(tokens, np.int16)}
    return make_motion(body, poses, transl, betas, fps=20, prompt="a test motion", **extra)


# -- numpy body view -------------------------------------------------------------------------------
def test_body_arrays_match_the_torch_body_model(openbody):
    arrays = load_body_arrays("openbody")
    betas = np.random.default_rng(0).normal(0, 1, (3, 10))
    ref_j = openbody.rest_joints(betas).numpy()
    ref_v = openbody.rest_vertices(betas).numpy()
    assert arrays.name == openbody.name and arrays.num_vertices == openbody.num_vertices
    assert np.abs(arrays.rest_joints(betas) - ref_j).max() < 1e-5
    assert np.abs(arrays.rest_vertices(betas) - ref_v).max() < 1e-5
    assert np.array_equal(arrays.faces, openbody.faces)
    assert np.abs(arrays.skin_weights - openbody.skin_weights).max() == 0
    # shape key i = the rest shape for the unit beta i
    from shapemove.core.scene.shape_keys import shape_key_coords

    keys = shape_key_coords(arrays.v_template, arrays.shapedirs)
    assert np.abs(keys[3] - openbody.rest_vertices(np.eye(10)[3]).numpy()[0]).max() < 1e-5


def test_phenotype_map_matches_openbody_and_inverts(openbody):
    arrays = load_body_arrays("openbody")
    p = np.array([0.3, 40.0, 0.5, 0.4, 0.45, 0.6])
    with np.load(openbody.path) as z:  # the asset's own linear map, applied by hand
        want = z["phenotype_intercept"] + p @ z["phenotype_matrix"]
    assert np.abs(arrays.betas_from_phenotype(p) - want).max() < 1e-9
    assert np.abs(openbody.betas_from_phenotype(p) - want).max() < 1e-5  # float32
    # phenotype -> betas -> phenotype (least squares) is the identity inside the slider ranges
    assert np.abs(arrays.phenotype_from_betas(arrays.betas_from_phenotype(p)) - p).max() < 1e-6
    with pytest.raises(ShapeMoveError, match="phenotype must be 6 values"):
        arrays.betas_from_phenotype([1.0, 2.0])


def test_smpl_file_arrays_match_the_smpl_family_body(tmp_path):
    sys.path.insert(0, str(ROOT / "tests"))
    from synthetic_smpl import write_model

    from shapemove.core.body.smpl_family import SMPLFamilyBody

    for family in ("smpl", "smplx"):
        path = tmp_path / f"{family.upper()}_NEUTRAL.pkl"
        write_model(path, family, chumpy=True)
        arrays, body = load_smpl_arrays(path), SMPLFamilyBody.load(path)
        betas = np.random.default_rng(1).normal(0, 1, 10)
        assert arrays.name == body.name
        assert np.abs(arrays.rest_joints(betas) - body.rest_joints(betas).numpy()).max() < 1e-5
        assert np.abs(arrays.skin_weights - body.skin_weights).max() < 1e-6


def test_scene_bodies_fall_back_to_numpy_without_torch(tmp_path, openbody):
    """With torch unimportable, load_body gives BodyArrays and rig_data is the same as with torch."""
    from shapemove.core.scene.rig_data import rig_data

    betas = np.random.default_rng(2).normal(0, 1, 10)
    ref = rig_data(openbody, betas)
    script = (
        "import sys, numpy as np; sys.modules['torch'] = None\n"
        "from shapemove.core.scene.bodies import load_body\n"
        "from shapemove.core.scene.rig_data import rig_data\n"
        "from shapemove.core.errors import ShapeMoveError\n"
        f"b = load_body('openbody-v1'); r = rig_data(b, np.array({betas.tolist()}))\n"
        "try:\n    load_body('smpl-neutral'); err = ''\nexcept ShapeMoveError as e:\n    err = str(e)\n"
        f"np.savez(r'{tmp_path / 'r.npz'}', heads=r.bones.heads, keys=r.key_coords[:, ::97], rolls=r.bones.rolls,\n"
        "         kind=type(b).__name__, torch=str('torch' in sys.modules and sys.modules['torch'] is not None), err=err)\n"
    )
    subprocess.run([sys.executable, "-c", script], check=True, timeout=120)
    z = np.load(tmp_path / "r.npz")
    assert str(z["kind"]) == "BodyArrays" and str(z["torch"]) == "False"
    assert np.abs(z["heads"] - ref.bones.heads).max() < 1e-5
    assert np.abs(z["rolls"] - ref.bones.rolls).max() < 1e-4
    assert np.abs(z["keys"] - ref.key_coords[:, ::97]).max() < 1e-5
    assert "smpl-neutral" in str(z["err"]) and "model file" in str(z["err"])


# -- worker ops ------------------------------------------------------------------------------------
def test_panel_ops_are_registered_and_check_their_input(tmp_path):
    from shapemove.core.worker import jobs_shapemove
    from shapemove.core.worker.client import InProcessRunner

    jobs = jobs_shapemove.register({})
    assert set(jobs) == {"generate", "redecode", "retarget", "search", "train", "betas_from_text"}
    runner = InProcessRunner(jobs)
    try:
        with pytest.raises(ShapeMoveError, match="dataset folder not found"):
            runner.call("train", {"kind": "vae", "data": str(tmp_path / "nope"), "model_dir": str(tmp_path / "m")})
        with pytest.raises(ShapeMoveError, match="kind must be one of vae, t5, tma"):
            runner.call("train", {"kind": "gan", "data": str(tmp_path), "model_dir": str(tmp_path / "m")})
        with pytest.raises(ShapeMoveError, match="'out' must be a .npz"):
            runner.call("retarget", {"source": "x.bvh", "out": str(tmp_path / "x.txt")})
        with pytest.raises(ShapeMoveError, match="source file not found"):
            runner.call("retarget", {"source": str(tmp_path / "x.bvh"), "out": str(tmp_path / "x.npz")})
        with pytest.raises(ShapeMoveError, match="model folder not found"):
            runner.call("generate", {"prompt": "a person waves", "model": str(tmp_path / "none"),
                                     "out": str(tmp_path / "g.npz")})
        with pytest.raises(ShapeMoveError, match="'betas' must be 10 finite numbers"):
            runner.call("redecode", {"motion": "m.npz", "betas": [1, 2], "out": str(tmp_path / "r.npz")})
    finally:
        runner.stop()


def test_betas_from_text_op_reaches_the_stated_height():
    from shapemove.core.worker import jobs_shapemove

    out = jobs_shapemove.betas_from_text({"text": SHAPE_TEXT}, lambda *a: None, lambda: False)
    assert out["measurements"] == {"height_cm": 185.0}
    assert abs(out["achieved"]["height_cm"] - 185.0) < 1.0 and len(out["betas"]) == 10


def test_naive_retarget_op_writes_a_motion_for_the_given_body(mocap_root, tmp_path, openbody):
    from shapemove.core.scene.motion_file import load_motion
    from shapemove.core.worker import jobs_shapemove

    clip = next(mocap_root.rglob("dataset-2_raise-up-both-hands_feminine_007*.bvh"))
    betas = [1.0, -0.5] + [0.0] * 8
    out = jobs_shapemove.retarget({"source": str(clip), "betas": betas, "method": "naive",
                                   "out": str(tmp_path / "r.npz")}, lambda *a: None, lambda: False)
    m = load_motion(out["path"])
    assert out["method"] == "naive" and m.body_model == openbody.name and out["frames"] == m.num_frames > 20
    assert np.allclose(m.betas, betas) and m.fps == 20


# -- real Blender --------------------------------------------------------------------------------
def _extension_zip(out: Path) -> str:
    spec = importlib.util.spec_from_file_location("build_extension", ROOT / "tools" / "build_extension.py")
    builder = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(builder)
    return str(builder.build(out))


@pytest.fixture(scope="module")
def ui(tmp_path_factory, openbody):
    need_module("bpy", "needs the bpy module (pip install bpy==5.0.1)")
    from shapemove.core.body.measure import measure
    from shapemove.core.body.shape_from_measurements import betas_from_shape_text

    d = tmp_path_factory.mktemp("blender_ui")
    betas = np.random.default_rng(5).normal(0, 0.8, 10).astype(np.float32)
    save_motion(d / "motion.npz", _motion(openbody, betas, 1, tokens=np.arange(3)))
    save_motion(d / "motion2.npz", _motion(openbody, betas, 2))
    (d / "corrupt.npz").write_bytes(b"this is not a zip file")
    (d / "export").mkdir()
    (d / "home").mkdir()
    config = dict(zip=_extension_zip(d / "dist"), motion=str(d / "motion.npz"), motion2=str(d / "motion2.npz"),
                  missing_motion=str(d / "missing.npz"), corrupt_motion=str(d / "corrupt.npz"), frames=FRAMES,
                  user_resources=str(d / "user"), home=str(d / "home"), export_dir=str(d / "export"),
                  shape_text=SHAPE_TEXT, zero_measure=measure(openbody, np.zeros(10, np.float32)),
                  text_betas=np.asarray(betas_from_shape_text(openbody, SHAPE_TEXT), np.float64).tolist())
    return blender_inside.run("test_ui.py", config, d)


@pytest.fixture(scope="module")
def ui_models(tmp_path_factory, tiny_bundle, mocap_root):
    """The jobs that need trained models, with the tiny models of the ``tiny_bundle`` fixture."""
    need_module("bpy", "needs the bpy module (pip install bpy==5.0.1)")
    model_dir, dataset = tiny_bundle
    d = tmp_path_factory.mktemp("blender_ui_models")
    (d / "home").mkdir()
    (d / "export").mkdir()
    bvh = next(Path(mocap_root).rglob("dataset-2_raise-up-both-hands_feminine_007.bvh"))
    config = dict(zip=_extension_zip(d / "dist"), model_dir=str(model_dir), dataset=str(dataset), bvh=str(bvh),
                  user_resources=str(d / "user"), home=str(d / "home"), export_dir=str(d / "export"))
    return blender_inside.run("test_ui_models.py", config, d)


@pytest.mark.blender
@pytest.mark.parametrize("name", blender_inside.inner_tests("test_ui.py"))
def test_ui_in_blender(ui, name):
    """One test of tests/in_blender/test_ui.py, run inside Blender (torch unimportable at first)."""
    blender_inside.check(ui, name)


@pytest.mark.blender
@pytest.mark.slow
@pytest.mark.parametrize("name", blender_inside.inner_tests("test_ui_models.py"))
def test_ui_jobs_in_blender(ui_models, name):
    """One test of tests/in_blender/test_ui_models.py (jobs with tiny trained models), inside Blender."""
    blender_inside.check(ui_models, name)
