"""The extension inside real Blender (bpy module): install the zip, build rigs with the operator,
check the scene, the forward kinematics, the skinning, shape changes, failure clean-up, a
headless Workbench render, the `blend` command and the MP4 of a saved scene.

All Blender work happens in one subprocess (tests/blender_checks.py): BLENDER_USER_RESOURCES has
to point at a temporary folder before bpy is imported. Its measurements are asserted here.
"""
from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import need_module

from shapemove.core.body.skeleton import JOINT_NAMES, PARENTS
from shapemove.core.scene.capsule_body import capsule_body
from shapemove.core.scene.motion_file import make_motion, save_motion

need_module("bpy", "needs the bpy module (pip install bpy==5.0.1)")
pytestmark = pytest.mark.blender

ROOT = Path(__file__).resolve().parents[1]
FRAMES = 40
MM = 1e-3


def _wavy_motion(body, frames, betas, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(frames)[:, None, None]
    poses = rng.normal(0, 0.4, (1, 24, 3)) * np.sin(0.2 * t + rng.uniform(0, 6, (1, 24, 3)))
    step = np.arange(frames)
    transl = np.stack([0.01 * step, 0.02 * np.sin(0.3 * step), 0.04 * step], -1)  # walks towards +Z (the front)
    return make_motion(body, poses, transl, betas, fps=20, prompt="a test motion")


def _smpl_format_file(body, path) -> str:
    """``body`` written as an SMPL model file (the keys of the official .npz): the extension
    loads a test body the way it loads a user's SMPL file, there is no test body by name."""
    np.savez(path, v_template=body.v_template.numpy(), shapedirs=body.shapedirs.numpy(),
             J_regressor=body.j_regressor.numpy(), weights=body.skin_weights, f=body.faces,
             kintree_table=np.stack([np.where(PARENTS < 0, 2 ** 32 - 1, PARENTS), np.arange(len(PARENTS))]))
    return str(path)


@pytest.fixture(scope="module")
def blender(tmp_path_factory, openbody):
    d = tmp_path_factory.mktemp("blender")
    spec = importlib.util.spec_from_file_location("build_extension", ROOT / "tools" / "build_extension.py")
    builder = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(builder)
    capsule = capsule_body()
    capsule_model = _smpl_format_file(capsule, d / "capsule_neutral.npz")  # loads as "smpl-neutral"
    motion = _wavy_motion(capsule, FRAMES, np.array([0.5, 0, 0, 0, 0, 0, 0, 0, 0, 0.3]))
    motion.body_model = "smpl-neutral"
    save_motion(d / "capsule.npz", motion)
    ob_motion = _wavy_motion(openbody, 12, np.random.default_rng(1).normal(0, 1, 10), seed=2)
    save_motion(d / "openbody.npz", ob_motion)
    motion.body_model = "mystery-body"
    save_motion(d / "bad.npz", motion)
    (d / "render").mkdir()
    config = dict(zip=str(builder.build(d / "dist")), motion=str(d / "capsule.npz"), bad_motion=str(d / "bad.npz"),
                  capsule_model=capsule_model,
                  openbody_motion=str(d / "openbody.npz"), user_resources=str(d / "user"),
                  results=str(d / "results.json"), render_dir=str(d / "render"), cli_blend=str(d / "cli" / "s.blend"))
    (d / "config.json").write_text(json.dumps(config))
    proc = subprocess.run([sys.executable, str(ROOT / "tests" / "blender_checks.py"), str(d / "config.json")],
                          capture_output=True, text=True, timeout=600)
    if proc.returncode != 0 or not (d / "results.json").exists():
        pytest.fail(f"blender_checks.py failed ({proc.returncode}):\n{proc.stderr[-4000:]}")
    results = json.loads((d / "results.json").read_text())
    results["_motion"] = motion
    print("blender timings (s):", {k: round(v, 2) for k, v in results["timings"].items()})
    return results


def _section(results, name):
    if name in results.get("errors", {}):
        pytest.fail(f"{name} raised in Blender:\n{results['errors'][name]}")
    return results[name]


def test_extension_installs_and_registers(blender):
    r = _section(blender, "install")
    assert r == {"result": ["FINISHED"], "enabled": True, "operator": True, "panel": True, "torch_imported": False}


def test_user_folder_is_the_extensions_user_path(blender):
    r = _section(blender, "user_dir")
    assert r["path"] == r["expected"] and r["in_user_resources"] and Path(r["path"]).is_dir()
    assert "extensions" in Path(r["path"]).parts and Path(r["path"]).name == "shapemove"


def test_operator_builds_mesh_shape_keys_armature_and_modifier(blender):
    r = _section(blender, "capsule")
    assert r["result"] == ["FINISHED"]
    assert r["new_objects"] == [["ShapeMove", "ARMATURE"], ["ShapeMove_body", "MESH"]]
    assert r["bystander_unchanged"]
    assert r["vertices"] == r["body_vertices"] == 768
    assert r["shape_keys"] == ["Basis"] + [f"beta_{i}" for i in range(10)]
    assert r["slider_ranges"] == [[-5.0, 5.0]] * 10
    assert np.allclose(r["key_values"], r["betas"], atol=1e-6)
    assert sorted(r["bones"]) == sorted(JOINT_NAMES) and r["vertex_groups"] == JOINT_NAMES
    assert r["bone_parents"] == {n: (JOINT_NAMES[p] if p >= 0 else None) for n, p in zip(JOINT_NAMES, PARENTS)}
    assert r["modifiers"] == [["ARMATURE", "ShapeMove"]] and r["mesh_parent"] == "ShapeMove"
    assert r["transforms_identity"]  # the Y-up -> Z-up turn lives in the data
    # bones sit on the rest joints (heads) with the rest frames the pose conversion assumed
    assert r["rest_head_error_m"] < 1e-5 and r["rest_matrix_error"] < 1e-4


def test_action_keys_every_frame_and_sets_the_scene_timing(blender):
    r = _section(blender, "capsule")
    assert r["frame_range"] == [1, FRAMES] and r["fps"] == r["motion_fps"] == 20
    assert r["fcurves"] == 24 * 4 + 3  # a quaternion per bone + the root location
    assert r["keys_per_fcurve"] == [FRAMES] and r["keyed_frames"] == list(range(1, FRAMES + 1))
    assert r["misgrouped_fcurves"] == []  # grouped per bone on every Blender (4.4 has no group_name=)


def test_evaluated_bones_and_mesh_follow_the_motion(blender):
    r = _section(blender, "capsule")
    assert r["fk_max_error_m"] < MM  # pose-bone heads == the motion's joints (Z-up)
    assert r["lbs_max_error_m"] < MM  # the Armature modifier == BodyModel.forward's skinning


def test_openbody_rig(blender, openbody):
    r = _section(blender, "openbody")
    assert r["result"] == ["FINISHED"]
    assert r["vertices"] == openbody.num_vertices and len(r["shape_keys"]) == 11
    assert r["keys_per_fcurve"] == [12] and r["frame_range"] == [1, 12]
    assert r["fk_max_error_m"] < MM and r["lbs_max_error_m"] < MM


def test_beta_slider_moves_the_bones(blender):
    r = _section(blender, "capsule")
    assert r["height_beta"] == 0  # the capsule body's height direction
    assert r["key_value_after"] == pytest.approx(2.5) and r["slider_value_after"] == pytest.approx(2.5)
    assert r["height_after"] - r["height_before"] == pytest.approx(r["height_expected_gain"], abs=1e-4)
    assert r["height_after"] > r["height_before"] + 0.1  # taller skeleton
    assert r["rest_heads_error_after_m"] < 1e-5
    # the same motion still plays exactly on the new body: joints and skin match BodyModel.forward
    assert r["fk_error_after_beta_m"] < MM and r["lbs_error_after_beta_m"] < MM


def test_shape_key_edit_is_caught_by_the_depsgraph_handler(blender):
    r = _section(blender, "capsule")
    assert r["handler_stale"] == ["ShapeMove"] and r["handler_scheduled"]
    assert r["handler_stale_after"] == [] and r["handler_rest_error_m"] < 1e-5


def test_failures_leave_the_file_as_it_was(blender):
    r = _section(blender, "failure")
    assert "mystery-body" in r.get("operator_error", "") and r["operator_counts_equal"]
    assert r["midway_raised"].startswith("ShapeMoveError") and "view layer" in r["midway_raised"]
    assert r["midway_counts_after"] == r["midway_counts_before"]
    assert r["mode_after"] == "OBJECT"


def test_headless_workbench_render_shows_the_body_moving(blender):
    r = _section(blender, "render")
    assert min(r["std_1"], r[f"std_{FRAMES}"]) > 0.05  # not blank
    assert all(f > 0.01 for f in r["body_fraction"])  # the body is in frame
    (y0, x0), (y1, x1) = r["centroids"]
    assert np.hypot(y1 - y0, x1 - x0) > 2.0 and r["changed_body_pixels"] > 0.01


def test_blend_command_saves_and_renders(blender):
    r = _section(blender, "cli")
    assert r["exit"] == 0 and r["png"] and r["blend"] and r["png_std"] > 0.05
    assert r["objects"] == ["ARMATURE", "CAMERA", "MESH", "MESH"] and r["camera"] and r["action"]
    assert r["frame_range"] == [1, FRAMES]


def test_render_video_writes_every_frame(blender):
    r = _section(blender, "video")  # the MP4, read back by Blender's movie clip loader
    assert r["frames"] == FRAMES and r["size"] == [64, 48] and r["no_tmp"]
