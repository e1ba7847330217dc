"""Retargeting onto the user's armature inside real Blender, as pytest tests in their own process
(started by tests/test_blender_rig_retarget.py through ``blender_inside.run``).

User-style armatures (Rigify / Mixamo / CC / unnamed, T- and A-poses, random bone rolls, a turned
and moved object, an FBX-style one with Y-up centimetre data in an object turned and scaled 0.01)
are built in the test, mapped by the "Map Bones" operator and baked by "Bake onto Rig"; the world
positions of the mapped bones that Blender evaluates are compared with the source motion's joints,
scaled. Also the headless function that `retarget-rig` runs, on a saved .blend.
The config ($SHAPEMOVE_BLENDER_CONFIG) names a work folder; the outer test reads the .blend the
tests save there.
"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest

CONFIG = json.loads(open(os.environ["SHAPEMOVE_BLENDER_CONFIG"]).read())
os.environ["BLENDER_USER_RESOURCES"] = CONFIG["user_resources"]
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/: rig_builders

import bpy  # noqa: E402
import mathutils  # noqa: E402
from rig_builders import SCHEMES, planted_motion, posed_joints, reproportion, wavy_motion, z_up  # noqa: E402

import shapemove.shapemove_addon as addon  # noqa: E402
from shapemove.core.scene.bone_map import SMPL22  # noqa: E402
from shapemove.core.scene.capsule_body import REST_JOINTS  # noqa: E402
from shapemove.core.scene.motion_file import save_motion  # noqa: E402
from shapemove.shapemove_addon import rig_retarget  # noqa: E402

MM = 1e-3
WORK = Path(CONFIG["dir"])


def _turned(deg, move, scale):
    a = np.radians(deg)
    M = np.eye(4)
    M[:3, :3] = scale * np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    M[:3, 3] = move
    return M


CASES = {c["name"]: c for c in [
    dict(name="rigify_A", scheme="rigify", pose="A", scale=1.1, motion="wavy", seed=1),
    dict(name="mixamo_T", scheme="mixamo", pose="T", scale=0.9, motion="wavy", seed=2, save_blend="mixamo_in.blend"),
    dict(name="cc_A", scheme="cc", pose="A", scale=1.0, motion="wavy", seed=3, preset="cc_iclone"),
    dict(name="unnamed_A", scheme="unnamed", pose="A", scale=1.2, motion="wavy", seed=4, preset_file="unnamed_map.json"),
    dict(name="mixamo_turned", scheme="mixamo", pose="A", scale=0.5, motion="wavy", seed=5,
         matrix_world=_turned(90, [2.0, -1.0, 0.0], 2.0)),
    dict(name="fbx_style", scheme="mixamo", pose="A", scale=1.0, motion="wavy", seed=7, data_in_object_space=True,
         matrix_world=np.array([[0.01, 0, 0, 0], [0, 0, -0.01, 0], [0, 0.01, 0, 0], [0, 0, 0, 1]])),
    dict(name="planted", scheme="rigify", pose="A", scale=1.0, motion="planted", seed=6, reproportion=True,
         plant_feet=True),
]}


def build_armature(name, bones, matrix_world):
    arm = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, arm)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")
    for bname, parent, head, tail, roll, deform in bones:
        eb = arm.edit_bones.new(bname)
        eb.head, eb.tail, eb.roll = tuple(head), tuple(tail), roll
        eb.use_deform = deform
        if parent:
            eb.parent = arm.edit_bones[parent]
            eb.use_connect = False
    bpy.ops.object.mode_set(mode="OBJECT")
    obj.matrix_world = mathutils.Matrix([list(r) for r in np.asarray(matrix_world)])  # rows
    return obj


def joints_in_blender(obj, mapping, frames):
    """(T,22,3) world positions of the mapped bones' heads as Blender evaluates them."""
    out = np.full((frames, 22, 3), np.nan)
    scene = bpy.context.scene
    for t in range(frames):
        scene.frame_set(1 + t)
        mw = np.array(obj.matrix_world)
        for j, bone in mapping.items():
            h = np.array(obj.pose.bones[bone].head)
            out[t, SMPL22.index(j)] = mw[:3, :3] @ h + mw[:3, 3]
    return out


@pytest.fixture(scope="module")
def motions():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon.register()
    out = {"wavy": wavy_motion(REST_JOINTS, 30, seed=1), "planted": planted_motion(REST_JOINTS, 40)}
    return {k: (m, str(save_motion(WORK / f"{k}.npz", m))) for k, m in out.items()}


def bake(motions, name):
    """Build case ``name``, map it with the operator, bake with the operator -> (object, map, the
    rig's joints, Blender-evaluated mapped joints (T,22,3) in world space)."""
    case = CASES[name]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    J = posed_joints(REST_JOINTS[:22], scale=case["scale"], pose=case["pose"])
    if case.get("reproportion"):
        J = reproportion(J)
        J[:, 2] -= J[[10, 11], 2].min() - 0.02
    bones = SCHEMES[case["scheme"]](J, np.random.default_rng(case["seed"]))
    M = np.asarray(case.get("matrix_world", np.eye(4)), dtype=np.float64)
    if case.get("data_in_object_space"):  # bones given in world space: store them in the object's space
        inv = np.linalg.inv(M)
        bones = [(n, p, inv[:3, :3] @ h + inv[:3, 3], inv[:3, :3] @ t + inv[:3, 3], r, d) for n, p, h, t, r, d in bones]
    obj = build_armature(name, bones, M)
    s = bpy.context.scene.shapemove_rig
    s.target = obj
    s.preset = case.get("preset", "AUTO")
    assert bpy.ops.shapemove.rig_map_auto() == {"FINISHED"}
    mapping = rig_retarget.stored_map(obj)
    motion, path = motions[case["motion"]]
    s.motion_path = path
    s.plant_feet = case.get("plant_feet", False)
    assert bpy.ops.shapemove.retarget_rig() == {"FINISHED"}
    return obj, mapping, J, joints_in_blender(obj, mapping, motion.num_frames)


def _scaled_source(motion, scale, matrix=np.eye(3)):
    return scale * z_up(motion.joints.astype(np.float64)) @ matrix.T


def _check_follows(motions, name):
    """Every mapped joint within 0.5 mm of the source joint x scale, up to one constant vertical
    offset (floor to floor); the action keys 30 frames at 20 fps."""
    obj, mapping, _, got = bake(motions, name)
    scene = bpy.context.scene
    assert len(mapping) >= 20 and scene.frame_end == 30 and abs(scene.render.fps / scene.render.fps_base - 20) < 1e-6
    assert obj.animation_data.action is not None
    src = _scaled_source(motions["wavy"][0], CASES[name]["scale"])
    cols = [i for i in range(22) if not np.isnan(got[0, i, 0])]
    diff = got[:, cols] - src[:, cols]
    offset = diff.reshape(-1, 3).mean(0)
    assert np.abs(offset[:2]).max() < 0.5 * MM
    err = np.abs(diff - offset).max()
    assert err < 0.5 * MM, (name, err)
    return obj, mapping, got


def test_rigify_a_pose_follows_the_scaled_source(motions):
    _check_follows(motions, "rigify_A")


def test_cc_preset_follows_the_scaled_source(motions):
    _check_follows(motions, "cc_A")


def test_fbx_style_object_follows_the_scaled_source(motions):
    _check_follows(motions, "fbx_style")


def test_unnamed_bones_follow_and_the_map_saves_and_loads(motions):
    obj, mapping, _ = _check_follows(motions, "unnamed_A")
    assert len(mapping) == 22
    path = WORK / CASES["unnamed_A"]["preset_file"]
    assert bpy.ops.shapemove.rig_map_save(filepath=str(path)) == {"FINISHED"}
    obj.shapemove_bone_map.clear()
    assert bpy.ops.shapemove.rig_map_load(filepath=str(path)) == {"FINISHED"}
    assert rig_retarget.stored_map(obj) == mapping
    saved = json.loads(path.read_text())
    assert saved["format"] == "shapemove-bone-map" and saved["bones"]["left_hip"] == [mapping["left_hip"]]


def test_bake_on_a_turned_moved_scaled_object(motions):
    _, _, _, got = bake(motions, "mixamo_turned")
    M = CASES["mixamo_turned"]["matrix_world"]
    src = _scaled_source(motions["wavy"][0], 1.0, M[:3, :3] / 2.0)
    cols = [i for i in range(22) if not np.isnan(got[0, i, 0])]
    d = got[:, cols] - src[:, cols]
    assert np.abs(d - d.reshape(-1, 3).mean(0)).max() < 0.5 * MM
    np.testing.assert_allclose(d.reshape(-1, 3).mean(0)[:2], M[:2, 3], atol=0.5 * MM)


def test_feet_planted_on_other_proportions(motions):
    """Rigify-style rig with shorter thighs and longer shins, A-pose: ankles hold within 1 mm while
    the source stands (its pelvis bobbing and turning), at the rig's own ankle height."""
    _, _, rest, got = bake(motions, "planted")
    slide = np.ptp(got[:, [7, 8]], axis=0).max()
    assert slide < 1 * MM, slide
    np.testing.assert_allclose(got[:, 7, 2], rest[7, 2], atol=2 * MM)
    assert np.ptp(got[:, 0, 2]) > 0.03  # the pelvis really moves (the test is not trivially still)


def test_mixamo_t_pose_follows_and_the_headless_bake_of_its_blend_matches(motions):
    """The T-posed Mixamo rig follows the source; saved without its action and map, the headless
    function (what `retarget-rig` runs) bakes the same joints within 0.05 mm. Leaves
    mixamo_in.blend in the work folder for the outer CLI test."""
    obj, _, got = _check_follows(motions, "mixamo_T")
    blend = WORK / CASES["mixamo_T"]["save_blend"]
    obj.animation_data.action = None
    obj.shapemove_bone_map.clear()
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    out = WORK / "headless_out.blend"
    facts = rig_retarget.retarget_rig_file(motions["wavy"][1], str(blend), "mixamo_T", str(out), preset=None,
                                           plant_feet=False)
    assert facts["frames"] == 30 and facts["mapping"].startswith("22 of 22") and "Mixamo" in facts["mapping"]
    bpy.ops.wm.open_mainfile(filepath=str(out))
    obj = bpy.data.objects["mixamo_T"]
    headless = joints_in_blender(obj, rig_retarget.stored_map(obj), facts["frames"])
    np.testing.assert_allclose(headless, got, atol=0.05 * MM)
