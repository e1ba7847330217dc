"""The ShapeMove panels and operators inside real Blender (bpy module), the numpy body view used
there without torch, and the worker ops behind the panels.

The Blender part runs in one subprocess (tests/blender_ui_checks.py; BLENDER_USER_RESOURCES must
be set before bpy is imported); its measurements are asserted here.
"""
from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import need_module
from tiny_models import tiny_bundle  # noqa: F401  (session fixture)

from shapemove.core.body.body_arrays import load_body_arrays, load_smpl_arrays
from shapemove.core.errors import ShapeMoveError
from shapemove.core.scene.motion_file import make_motion, save_motion

ROOT = Path(__file__).resolve().parents[1]
FRAMES = 12
MM = 1e-3
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
    keys = arrays.shape_key_coords()
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


def _run_checks(d: Path, config: dict) -> dict:
    (d / "config.json").write_text(json.dumps(config))
    proc = subprocess.run([sys.executable, str(ROOT / "tests" / "blender_ui_checks.py"), str(d / "config.json")],
                          capture_output=True, text=True, timeout=600)
    if proc.returncode != 0 or not (d / "results.json").exists():
        pytest.fail(f"blender_ui_checks.py failed ({proc.returncode}):\n{proc.stderr[-4000:]}")
    results = json.loads((d / "results.json").read_text())
    print("blender ui timings (s):", {k: round(v, 2) for k, v in results["timings"].items()})
    return results


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
                  missing_motion=str(d / "missing.npz"), corrupt_motion=str(d / "corrupt.npz"),
                  user_resources=str(d / "user"), home=str(d / "home"), export_dir=str(d / "export"),
                  results=str(d / "results.json"), shape_text=SHAPE_TEXT)
    results = _run_checks(d, config)
    results["_betas"] = betas
    results["_zero_measure"] = measure(openbody, np.zeros(10, np.float32))
    results["_text_betas"] = betas_from_shape_text(openbody, SHAPE_TEXT)
    return results


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
                  user_resources=str(d / "user"), home=str(d / "home"), export_dir=str(d / "export"),
                  results=str(d / "results.json"))
    results = _run_checks(d, config)
    results["_user"] = str(d / "user")
    return results


def _section(results, name):
    if name in results.get("errors", {}):
        pytest.fail(f"{name} raised in Blender:\n{results['errors'][name]}")
    return results[name]


PANELS = ["SHAPEMOVE_PT_export", "SHAPEMOVE_PT_generate", "SHAPEMOVE_PT_library", "SHAPEMOVE_PT_main",
          "SHAPEMOVE_PT_retarget", "SHAPEMOVE_PT_shape", "SHAPEMOVE_PT_shape_betas", "SHAPEMOVE_PT_train"]


@pytest.mark.blender
def test_panels_register_and_draw_in_the_factory_scene(ui):
    r = _section(ui, "install")
    assert r["result"] == ["FINISHED"] and r["enabled"] and r["panels"] == PANELS and not r["torch_imported"]
    e = _section(ui, "draw_empty")
    assert e["active"] == "Cube"  # factory startup scene
    panels = e["panels"]
    # rig panels hide without a rig; the others draw their inputs and start buttons
    assert panels["SHAPEMOVE_PT_shape"] is None and panels["SHAPEMOVE_PT_export"] is None
    ops = {p: [d["op"] for d in items if d["kind"] == "operator"] for p, items in panels.items() if items}
    assert ops["SHAPEMOVE_PT_generate"] == ["shapemove.generate"]
    assert ops["SHAPEMOVE_PT_retarget"] == ["shapemove.retarget"]
    assert ops["SHAPEMOVE_PT_library"] == ["shapemove.library_search"]
    assert ops["SHAPEMOVE_PT_train"] == ["shapemove.train", "shapemove.train"]
    assert [d["props"] for d in panels["SHAPEMOVE_PT_train"] if d["kind"] == "operator"] == [{"resume": False}, {"resume": True}]
    props = [d["prop"] for d in panels["SHAPEMOVE_PT_generate"] if d["kind"] == "prop"]
    assert props == ["prompt", "shape_text", "use_seconds", "seconds", "seed", "temperature"]
    prefs = [d["prop"] for d in e["preferences"] if d["kind"] == "prop"]
    assert prefs == ["body_model", "python_env", "models_dir", "active_model", "device"]


@pytest.mark.blender
def test_rig_from_a_motion_file_without_torch(ui):
    r = _section(ui, "build")
    assert r["result"] == ["FINISHED"] and r["new_objects"] == 2
    assert r["body_type"] == "BodyArrays" and not r["torch_imported"]
    assert r["has_tokens"] and r["motion_file"].endswith("motion.npz") and r["frames"] == FRAMES
    assert r["rest_error_m"] < 1e-5
    d = _section(ui, "draw_rig")
    assert d["semantic_props"] == ["height", "weight", "age", "muscle", "gender", "proportions"]
    assert d["beta_props"] == list(range(10))
    export_ops = [x for x in d["panels"]["SHAPEMOVE_PT_export"] if x["kind"] == "operator"]
    assert export_ops == [{"kind": "operator", "op": "shapemove.export", "text": "Export", "props": {"format": "FBX"}}]


@pytest.mark.blender
def test_redecoded_motion_replaces_the_keys(ui):
    r = _section(ui, "apply_motion")
    assert r["fk_error_m"] < MM  # the rig now plays motion 2 exactly
    assert r["actions_after"] == r["actions_before"] and r["same_name"] and r["frames"] == FRAMES


@pytest.mark.blender
def test_semantic_height_slider_makes_the_skeleton_taller(ui):
    r = _section(ui, "semantic")
    assert r["slider_after"] == pytest.approx(r["slider_before"] + 0.1, abs=1e-6)
    assert np.allclose(r["betas_delta"], r["expected_delta"], atol=1e-5)  # exactly 0.1 x the height row
    assert r["height_after"] > r["height_before"] + 0.02 and r["rest_error_m"] < 1e-5
    assert r["weight_unchanged"]
    assert r["redecode_pending"] == ["Rig"] and r["redecode_timer"]  # the motion follows (debounced job)


@pytest.mark.blender
def test_random_and_reset(ui):
    r = _section(ui, "random_reset")
    assert r["random"] == r["reset"] == ["FINISHED"]
    assert np.allclose(r["betas_random"], r["expected_random"], atol=1e-6)
    assert r["rest_error_random_m"] < 1e-5
    assert r["betas_reset"] == [0.0] * 10 and r["rest_error_reset_m"] < 1e-5


@pytest.mark.blender
def test_exports_reimport_with_the_same_bones_and_frames(ui):
    r = _section(ui, "export")
    assert r["rig_bones"] == 24 and r["rig_frames"] == FRAMES
    for fmt in ("FBX", "GLTF", "BVH"):
        assert r[fmt]["size"] > 1000 and r[fmt]["no_tmp"], fmt
        assert r[fmt]["bones"] == 24, (fmt, r[fmt])
        assert r[fmt]["frames"] == FRAMES, (fmt, r[fmt])
    # the body comes back with its 10 shape keys (+ Basis) from FBX and glTF (the glTF importer
    # may add a small bone-shape mesh); BVH is skeleton only
    body = [r["rig_vertices"], 11]
    assert [m for m in r["FBX"]["meshes"] if m[0] == r["rig_vertices"]] == [body]
    assert [m for m in r["GLTF"]["meshes"] if m[0] == r["rig_vertices"]] == [body]
    assert r["BVH"]["meshes"] == []
    assert r["operator"] == ["ok", ["FINISHED"]] and r["operator_file"]


@pytest.mark.blender
def test_bad_input_is_reported_and_changes_nothing(ui):
    r = _section(ui, "errors_reported")
    assert r["missing_file"][0] == "error" and "motion file not found" in r["missing_file"][1]
    assert r["corrupt_file"][0] == "error" and "cannot read motion file" in r["corrupt_file"][1]
    assert r["empty_prompt"][0] == "error" and "prompt is empty" in r["empty_prompt"][1]
    assert r["retarget_missing"][0] == "error" and "motion file not found" in r["retarget_missing"][1]
    assert r["train_missing"][0] == "error" and "dataset folder not found" in r["train_missing"][1]
    assert r["counts_equal"]


@pytest.mark.blender
def test_measure_job_in_process_updates_the_rig(ui):
    r = _section(ui, "measure_job")
    assert r["result"] == ["FINISHED"] and r["running_after_submit"] and r["finished"]
    assert r["runner"] == "InProcessRunner" and r["betas"] == [0.0] * 10 and r["height_before"] == 0.0
    assert r["height_cm"] == pytest.approx(ui["_zero_measure"]["height_cm"], abs=0.05)
    assert r["waist_cm"] == pytest.approx(ui["_zero_measure"]["waist_cm"], abs=0.05)
    # while the job ran, the Shape panel showed its progress and a Cancel button
    kinds = [d["kind"] for d in r["panel_while_running"]]
    assert "progress" in kinds and {"kind": "operator", "op": "shapemove.cancel_job", "text": "",
                                    "props": {"kind": "measure"}} in r["panel_while_running"]


@pytest.mark.blender
def test_shape_from_text_job_sets_the_betas(ui):
    r = _section(ui, "shape_text_job")
    assert r["result"] == ["FINISHED"] and r["finished"]
    assert np.allclose(r["betas"], ui["_text_betas"], atol=1e-5)
    assert r["height_cm"] == pytest.approx(185.0, abs=1.0) and r["skeleton_after"] > r["skeleton_before"]


@pytest.mark.blender
def test_missing_or_dead_worker_is_an_error_and_changes_nothing(ui):
    r = _section(ui, "dead_worker")
    assert r["missing_python"][0] == "error" and "Python environment not found" in r["missing_python"][1]
    assert r["submit"] == ["ok", ["FINISHED"]] and r["finished"]
    assert len(r["job_errors"]) == 1 and "worker process died" in r["job_errors"][0]
    assert r["counts_equal"] and r["height_unchanged"]


# -- jobs with trained (tiny) models -----------------------------------------------------------------
@pytest.mark.blender
@pytest.mark.slow
def test_generate_builds_a_rig_from_the_job(ui_models):
    r = _section(ui_models, "generate")
    assert r["result"] == ["FINISHED"] and r["finished"] and r["errors"] == []
    assert r["new"] == ["ARMATURE", "MESH"] and r["active_is_rig"] and r["has_tokens"]
    assert r["frames"] == 40  # 2 s at 20 fps
    assert 120 < r["height_cm"] < 220  # the measurements came back with the motion
    # written under the extension's user folder (bpy.utils.extension_path_user), not the package
    assert r["data_dir"] == os.path.join(ui_models["_user"], "extensions", ".user", "user_default", "shapemove", "data")


@pytest.mark.blender
@pytest.mark.slow
def test_shape_change_redecodes_the_motion(ui_models):
    r = _section(ui_models, "redecode")
    assert r["pending"] and r["finished"] and r["errors"] == [] and r["file"]
    assert r["betas_match"] and r["tokens_match"]  # same tokens, decoded for the new body
    assert r["fk_error_m"] < MM  # the rig plays the re-decoded motion


@pytest.mark.blender
@pytest.mark.slow
def test_library_search_and_import(ui_models):
    r = _section(ui_models, "library")
    assert r["search"] == ["FINISHED"] and r["finished"] and r["errors"] == []
    assert len(r["items"]) == 3 and r["list_rows"] == [3]
    scores = [i[1] for i in r["items"]]
    assert scores == sorted(scores, reverse=True) and all(-1 <= x <= 1 for x in scores)
    assert r["import"] == ["FINISHED"] and r["import_finished"]
    assert r["new"] == ["ARMATURE", "MESH"] and r["rig_frames"] > 10


@pytest.mark.blender
@pytest.mark.slow
def test_retarget_the_active_armatures_action_onto_a_rig(ui_models):
    r = _section(ui_models, "retarget_action")
    assert r["source_type"] == "ARMATURE" and r["result"] == ["FINISHED"] and r["finished"] and r["errors"] == []
    assert r["new"] == ["ARMATURE", "MESH"] and r["frames"] > 20
    assert r["betas_error"] < 1e-5  # the target rig's body
    assert len(r["bvh_written"]) == 1  # the action went to the worker as a BVH in the data folder


@pytest.mark.blender
@pytest.mark.slow
def test_train_job_publishes_a_selectable_model(ui_models):
    r = _section(ui_models, "train")
    assert r["result"] == ["FINISHED"] and r["running"] and r["finished"] and r["errors"] == []
    assert r["train_result"].endswith("trained") and r["tma_file"]
    assert r["use"] == ["ok", ["FINISHED"]] and r["active_model"] == r["train_result"]
