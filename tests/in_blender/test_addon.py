"""The extension inside real Blender (bpy module), as pytest tests that run in their own process:
install the zip into a temporary user folder, build rigs with the operator, check the scene, the
forward kinematics, the skinning, shape changes, failure clean-up, a headless Workbench render,
the `blend` command and the MP4 of a saved scene.

Started by tests/test_blender_addon.py (``blender_inside.run``): BLENDER_USER_RESOURCES has to
point at a temporary folder before bpy is imported, so this module never runs in the main test
process (tests/conftest.py leaves the folder out). The config (JSON) is named by
$SHAPEMOVE_BLENDER_CONFIG. Tests run in file order and share the scene through module fixtures.
"""
from __future__ import annotations

import importlib
import json
import os
import sys

import numpy as np
import pytest

CONFIG = json.loads(open(os.environ["SHAPEMOVE_BLENDER_CONFIG"]).read())
os.environ["BLENDER_USER_RESOURCES"] = CONFIG["user_resources"]

import bpy  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # tests/: bpy_readback
from bpy_readback import bone_heads_world, evaluated_vertices  # noqa: E402

ADDON = "bl_ext.user_default.shapemove"
FRAMES = CONFIG["frames"]
MM = 1e-3


def ext(name):
    """A module of the installed extension (bl_ext.user_default.shapemove.<name>)."""
    return importlib.import_module(f"{ADDON}.{name}")


def datablock_counts():
    return {k: len(getattr(bpy.data, k)) for k in ("objects", "meshes", "armatures", "actions", "shape_keys", "collections")}


def build(motion_path, model_file=""):
    """Build a rig with the operator beside a bystander object -> (motion, body, armature, mesh, new objects)."""
    motion = ext("core.scene.motion_file").load_motion(motion_path)
    body = ext("core.scene.bodies").load_body(motion.body_model, model_file or None)
    bystander = bpy.data.objects.new("Bystander", None)
    bpy.context.scene.collection.objects.link(bystander)
    bystander.location = (1.0, 2.0, 3.0)
    before = set(bpy.data.objects)
    result = bpy.ops.shapemove.build_from_motion(filepath=motion_path, body_model_file=model_file)
    new = set(bpy.data.objects) - before
    assert sorted(result) == ["FINISHED"]
    assert tuple(bystander.location) == (1.0, 2.0, 3.0) and bystander.parent is None  # left alone
    arm = next(o for o in new if o.type == "ARMATURE")
    mesh = next(o for o in new if o.type == "MESH")
    return motion, body, arm, mesh, new


def fk_and_lbs_errors(motion, body, arm, mesh, frames, betas=None, vertical_free=False):
    """Max |evaluated bone head - BodyModel joint| and |evaluated vertex - BodyModel vertex| (m).
    ``vertical_free``: up to one vertical shift per frame (a shape change re-grounds the feet)."""
    import torch

    axes = ext("core.scene.axes")
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    b = torch.as_tensor(motion.betas if betas is None else betas, dtype=torch.float32)[None]
    fk, lbs = [], []
    for k in frames:
        bpy.context.scene.frame_set(1 + k)
        out = body.forward(b, torch.as_tensor(motion.poses[k:k + 1]), torch.as_tensor(motion.transl[k:k + 1]))
        d = bone_heads_world(arm, names[:22]) - axes.points_to_z_up(out.joints[0, :22].numpy())
        up = np.array([0.0, 0.0, d[0, 2] if vertical_free else 0.0])
        fk.append(np.abs(d - up).max())
        lbs.append(np.abs(evaluated_vertices(mesh) - axes.points_to_z_up(out.vertices[0].numpy()) - up).max())
    return float(max(fk)), float(max(lbs))


def rest_errors(body, betas, arm):
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    layout = ext("core.scene.rig_data").rig_data(body, betas).bones
    rest = np.array([np.array(arm.data.bones[n].matrix_local) for n in names])
    return float(np.abs(rest[:, :3, 3] - layout.heads).max()), float(np.abs(rest[:, :3, :3] - layout.matrices).max())


# -- install ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def installed():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.ops.extensions.package_install_files(filepath=CONFIG["zip"], repo="user_default", enable_on_install=True)


def test_extension_installs_and_registers(installed):
    assert sorted(installed) == ["FINISHED"] and ADDON in bpy.context.preferences.addons
    assert hasattr(bpy.ops.shapemove, "build_from_motion") and hasattr(bpy.types, "SHAPEMOVE_PT_shape")
    assert "torch" not in sys.modules  # registering must not need torch


def test_user_folder_is_the_extensions_user_path(installed):
    # the installed extension keeps its files under bpy.utils.extension_path_user (4.2+)
    path = str(ext("shapemove_addon.paths").user_dir())
    assert path == bpy.utils.extension_path_user(ADDON) and path.startswith(CONFIG["user_resources"] + os.sep)
    assert os.path.isdir(path) and "extensions" in path.split(os.sep) and os.path.basename(path) == "shapemove"


# -- the capsule rig -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def capsule(installed):
    motion, body, arm, mesh, new = build(CONFIG["motion"], CONFIG["capsule_model"])
    return {"motion": motion, "body": body, "arm": arm, "mesh": mesh, "new": new}


def test_operator_builds_mesh_shape_keys_armature_and_modifier(capsule):
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    parents = ext("core.body.skeleton").PARENTS
    arm, mesh, motion = capsule["arm"], capsule["mesh"], capsule["motion"]
    assert sorted((o.name, o.type) for o in capsule["new"]) == [("ShapeMove", "ARMATURE"), ("ShapeMove_body", "MESH")]
    assert len(mesh.data.vertices) == capsule["body"].num_vertices == 768
    keys = mesh.data.shape_keys.key_blocks
    assert [k.name for k in keys] == ["Basis"] + [f"beta_{i}" for i in range(10)]
    assert [(k.slider_min, k.slider_max) for k in keys[1:]] == [(-5.0, 5.0)] * 10
    assert np.allclose([k.value for k in keys[1:]], motion.betas, atol=1e-6)
    assert sorted(b.name for b in arm.data.bones) == sorted(names) and [g.name for g in mesh.vertex_groups] == names
    assert {b.name: (b.parent.name if b.parent else None) for b in arm.data.bones} == \
        {n: (names[p] if p >= 0 else None) for n, p in zip(names, parents)}
    assert [(m.type, m.object.name if m.object else None) for m in mesh.modifiers] == [("ARMATURE", "ShapeMove")]
    assert mesh.parent is arm
    # the Y-up -> Z-up turn lives in the data, not in the object transforms
    assert np.allclose(np.array(arm.matrix_world), np.eye(4)) and np.allclose(np.array(mesh.matrix_world), np.eye(4))
    # bones sit on the rest joints (heads) with the rest frames the pose conversion assumed
    head_err, matrix_err = rest_errors(capsule["body"], motion.betas, arm)
    assert head_err < 1e-5 and matrix_err < 1e-4


def test_action_keys_every_frame_and_sets_the_scene_timing(capsule):
    scene = bpy.context.scene
    assert [scene.frame_start, scene.frame_end] == [1, FRAMES]
    assert scene.render.fps / scene.render.fps_base == capsule["motion"].fps == 20
    fcurves = ext("shapemove_addon.keyframes").action_fcurves(capsule["arm"].animation_data.action, capsule["arm"])
    assert len(fcurves) == 24 * 4 + 3  # a quaternion per bone + the root location
    assert {len(fc.keyframe_points) for fc in fcurves} == {FRAMES}
    assert sorted({int(round(k.co[0])) for fc in fcurves for k in fc.keyframe_points}) == list(range(1, FRAMES + 1))
    # grouped per bone on every Blender (4.4 has no group_name=): the Dope Sheet's channel list
    assert [fc.data_path for fc in fcurves if fc.group is None or fc.data_path.split('"')[1] != fc.group.name] == []


def test_evaluated_bones_and_mesh_follow_the_motion(capsule):
    frames = sorted({0, FRAMES // 3, FRAMES // 2, FRAMES - 1})
    fk, lbs = fk_and_lbs_errors(capsule["motion"], capsule["body"], capsule["arm"], capsule["mesh"], frames)
    assert fk < MM  # pose-bone heads == the motion's joints (Z-up)
    assert lbs < MM  # the Armature modifier == BodyModel.forward's skinning


def _height(arm):
    b = arm.data.bones
    return b["head"].head_local.z - b["left_ankle"].head_local.z


@pytest.fixture(scope="module")
def slider(capsule):
    """Beta 'height' (largest effect on head-to-ankle height) moved by 2 through the panel slider."""
    import torch

    body, arm, motion = capsule["body"], capsule["arm"], capsule["motion"]
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    jd = body.joint_shapedirs.numpy()  # (24,3,10) Y-up
    gain = jd[names.index("head"), 1] - jd[names.index("left_ankle"), 1]
    i = int(np.argmax(np.abs(gain)))
    step = 2.0 * np.sign(gain[i])
    h0 = _height(arm)
    bpy.context.view_layer.objects.active = arm
    arm.shapemove.betas[i] = float(motion.betas[i] + step)
    betas = motion.betas.astype(np.float64).copy()
    betas[i] += step
    rest = ext("core.scene.axes").points_to_z_up(body.rest_joints(torch.as_tensor(betas, dtype=torch.float32)[None])[0].numpy())
    return {"i": i, "h0": h0, "gain": float(abs(gain[i]) * 2.0), "betas": betas, "rest": rest, "names": names}


def test_beta_slider_moves_the_bones(capsule, slider):
    arm, mesh, i = capsule["arm"], capsule["mesh"], slider["i"]
    assert i == 0  # the capsule body's height direction
    assert mesh.data.shape_keys.key_blocks[f"beta_{i}"].value == pytest.approx(2.5)
    assert arm.shapemove.betas[i] == pytest.approx(2.5)
    assert _height(arm) - slider["h0"] == pytest.approx(slider["gain"], abs=1e-4) and slider["gain"] > 0.1
    heads = np.array([list(arm.data.bones[n].head_local) for n in slider["names"]])
    assert np.abs(heads - slider["rest"]).max() < 1e-5
    # the same motion still plays exactly on the new body: joints and skin match BodyModel.forward,
    # up to the vertical shift that puts the new body's feet on the floor (shapemove_addon/grounding.py)
    fk, lbs = fk_and_lbs_errors(capsule["motion"], capsule["body"], arm, mesh, [FRAMES // 2], slider["betas"],
                                vertical_free=True)
    assert fk < MM and lbs < MM


def test_shape_key_edit_is_caught_by_the_depsgraph_handler(capsule, slider):
    import torch

    sync = ext("shapemove_addon.shape_sync")
    arm, mesh, body = capsule["arm"], capsule["mesh"], capsule["body"]
    j = (slider["i"] + 1) % 10
    key = mesh.data.shape_keys.key_blocks[f"beta_{j}"]
    key.value = float(key.value + 1.0)  # edited in the Shape Keys list, not through the slider
    bpy.context.view_layer.update()
    assert [o.name for o in sync.stale_rigs(bpy.context.scene)] == ["ShapeMove"]
    assert bpy.app.timers.is_registered(sync._run_pending)
    sync._run_pending()  # the timer's work (timers do not run without Blender's event loop)
    assert sync.stale_rigs(bpy.context.scene) == []
    betas = slider["betas"].copy()
    betas[j] += 1.0
    rest = ext("core.scene.axes").points_to_z_up(body.rest_joints(torch.as_tensor(betas, dtype=torch.float32)[None])[0].numpy())
    heads = np.array([list(arm.data.bones[n].head_local) for n in slider["names"]])
    assert np.abs(heads - rest).max() < 1e-5


def test_failures_leave_the_file_as_it_was(capsule):
    # 1. bad input through the operator: a report, nothing created
    before = datablock_counts()
    with pytest.raises(RuntimeError, match="mystery-body"):  # bpy.ops raises on an ERROR report
        bpy.ops.shapemove.build_from_motion(filepath=CONFIG["bad_motion"])
    assert datablock_counts() == before
    # 2. a failure half-way (the target collection is not in the view layer, so the bones cannot
    #    be edited): everything created so far is removed again
    motion = ext("core.scene.motion_file").load_motion(CONFIG["motion"])
    body = ext("core.scene.bodies").load_body(motion.body_model, CONFIG["capsule_model"])
    loose = bpy.data.collections.new("NotInScene")
    before = datablock_counts()
    with pytest.raises(ext("core.errors").ShapeMoveError, match="view layer"):
        ext("shapemove_addon.scene_build").build_rig(bpy.context, motion, body, name="Broken", collection=loose)
    assert datablock_counts() == before and bpy.context.mode == "OBJECT"
    bpy.data.collections.remove(loose)


def test_headless_workbench_render_shows_the_body_moving(capsule):
    from PIL import Image

    render = ext("shapemove_addon.preview_render")
    rig, scene = capsule["arm"], bpy.context.scene
    for o in scene.objects:  # keep only the rig under test visible
        if o not in (rig, capsule["mesh"]):
            o.hide_render = True
    render.add_preview_stage(bpy.context, rig, resolution=(96, 72))
    masks = []
    for f in (scene.frame_start, scene.frame_end):
        path = os.path.join(CONFIG["render_dir"], f"frame_{f}.png")
        render.render_frame(scene, f, path)
        px = np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255
        assert px.std() > 0.05  # not blank
        masks.append(px[..., 0] - px[..., 2] > 0.2)  # the body is drawn in a warm flat colour
    assert all(m.mean() > 0.01 for m in masks)  # the body is in frame
    (y0, x0), (y1, x1) = [np.argwhere(m).mean(0) for m in masks]
    assert np.hypot(y1 - y0, x1 - x0) > 2.0 and (masks[0] ^ masks[1]).mean() > 0.01  # and it moved


def test_openbody_rig(installed):
    motion, body, arm, mesh, _ = build(CONFIG["openbody_motion"])
    assert len(mesh.data.vertices) == body.num_vertices and len(mesh.data.shape_keys.key_blocks) == 11
    fcurves = ext("shapemove_addon.keyframes").action_fcurves(arm.animation_data.action, arm)
    assert {len(fc.keyframe_points) for fc in fcurves} == {12}
    assert [bpy.context.scene.frame_start, bpy.context.scene.frame_end] == [1, 12]
    fk, lbs = fk_and_lbs_errors(motion, body, arm, mesh, [0, 5, 11])
    assert fk < MM and lbs < MM
    head_err, matrix_err = rest_errors(body, motion.betas, arm)
    assert head_err < 1e-5 and matrix_err < 1e-4


# -- command line (opens another file: keep these last) --------------------------------------------
@pytest.fixture(scope="module")
def cli_blend(installed):
    from shapemove.cli import main

    out, png = CONFIG["cli_blend"], os.path.join(CONFIG["render_dir"], "cli.png")
    code = main(["blend", "--motion", CONFIG["motion"], "--body-model-file", CONFIG["capsule_model"], "--out", out,
                 "--render", png, "--frame", "5", "--resolution", "64", "48"])
    return code, out, png


def test_blend_command_saves_and_renders(cli_blend):
    from PIL import Image

    code, out, png = cli_blend
    assert code == 0 and os.path.isfile(png) and os.path.isfile(out)
    assert np.asarray(Image.open(png).convert("RGB"), dtype=np.float64).std() / 255 > 0.05
    bpy.ops.wm.open_mainfile(filepath=out)
    scene = bpy.context.scene
    arm = bpy.data.objects.get("ShapeMove")
    assert sorted(o.type for o in scene.objects) == ["ARMATURE", "CAMERA", "MESH", "MESH"] and scene.camera is not None
    assert arm is not None and arm.animation_data is not None and arm.animation_data.action is not None
    assert [scene.frame_start, scene.frame_end] == [1, FRAMES]


def test_render_video_writes_every_frame(cli_blend):
    mp4 = os.path.join(CONFIG["render_dir"], "cli.mp4")
    ext("shapemove_addon.headless").render_video(cli_blend[1], mp4)
    clip = bpy.data.movieclips.load(mp4)  # the MP4, read back by Blender's movie clip loader
    assert clip.frame_duration == FRAMES and list(clip.size) == [64, 48]
    assert not any(".tmp" in f for f in os.listdir(CONFIG["render_dir"]))
