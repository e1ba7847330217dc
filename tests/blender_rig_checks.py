"""Run by test_blender_rig_retarget.py in a subprocess (bpy): build user-style armatures in real
Blender, map and bake ShapeMove motions onto them through the add-on's operators and headless
function, and record what Blender itself evaluates (pose-bone heads in world space per frame).

argv[1]: config JSON {motions: {name: path}, cases: [...], out: results .npz, blend_dir}.
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="sm_rig_user_"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402
import mathutils  # noqa: E402
import numpy as np  # noqa: E402

from rig_builders import SCHEMES, posed_joints, reproportion  # noqa: E402
from shapemove.core.scene.bone_map import SMPL22  # noqa: E402
from shapemove.core.scene.capsule_body import REST_JOINTS  # noqa: E402


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


def main(cfg):
    import shapemove.shapemove_addon as addon
    from shapemove.core.scene.motion_file import load_motion
    from shapemove.shapemove_addon import rig_retarget

    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon.register()
    results, info = {}, {}
    for case in cfg["cases"]:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        J = posed_joints(REST_JOINTS[:22], scale=case["scale"], pose=case["pose"])
        if case.get("reproportion"):
            J = reproportion(J)
            J[:, 2] -= J[[10, 11], 2].min() - 0.02
        bones = SCHEMES[case["scheme"]](J, np.random.default_rng(case.get("seed", 0)))
        M = np.asarray(case.get("matrix_world", np.eye(4).tolist()), dtype=np.float64)
        if case.get("data_in_object_space"):  # bones given in world space: store them in the object's space
            inv = np.linalg.inv(M)
            bones = [(n, p, inv[:3, :3] @ h + inv[:3, 3], inv[:3, :3] @ t + inv[:3, 3], r, d) for n, p, h, t, r, d in bones]
        obj = build_armature(case["name"], bones, M)
        scene = bpy.context.scene
        scene.shapemove_rig.target = obj
        scene.shapemove_rig.preset = case.get("preset", "AUTO")
        assert bpy.ops.shapemove.rig_map_auto() == {"FINISHED"}
        mapping = rig_retarget.stored_map(obj)
        motion_path = cfg["motions"][case["motion"]]
        scene.shapemove_rig.motion_path = motion_path
        scene.shapemove_rig.plant_feet = case.get("plant_feet", False)
        assert bpy.ops.shapemove.retarget_rig() == {"FINISHED"}
        T = load_motion(motion_path).num_frames
        results[case["name"]] = joints_in_blender(obj, mapping, T)
        results[case["name"] + "__rest"] = J
        info[case["name"]] = {"mapping": mapping, "action": obj.animation_data.action.name,
                              "fps": scene.render.fps / scene.render.fps_base, "frame_end": scene.frame_end}
        if case.get("preset_file"):  # the Save / Load operators round-trip the map through JSON
            assert bpy.ops.shapemove.rig_map_save(filepath=case["preset_file"]) == {"FINISHED"}
            obj.shapemove_bone_map.clear()
            assert bpy.ops.shapemove.rig_map_load(filepath=case["preset_file"]) == {"FINISHED"}
            info[case["name"]]["reloaded_map"] = rig_retarget.stored_map(obj)
        if case.get("save_blend"):
            obj.animation_data.action = None
            obj.shapemove_bone_map.clear()
            bpy.ops.wm.save_as_mainfile(filepath=case["save_blend"])
    # the headless function on a saved .blend (what `retarget-rig` runs)
    h = cfg["headless"]
    facts = rig_retarget.retarget_rig_file(h["motion"], h["blend"], h["armature"], h["out"], preset=h.get("preset"),
                                            plant_feet=h.get("plant_feet", True))
    bpy.ops.wm.open_mainfile(filepath=h["out"])
    obj = bpy.data.objects[h["armature"]]
    mapping = rig_retarget.stored_map(obj)
    results["headless"] = joints_in_blender(obj, mapping, facts["frames"])
    info["headless"] = {**facts, "bone_map": mapping}
    np.savez(cfg["out"], **results)
    Path(cfg["info"]).write_text(json.dumps(info))


if __name__ == "__main__":
    main(json.loads(Path(sys.argv[1]).read_text()))
