"""Put a ShapeMove motion on the user's own armature (Rigify, Mixamo, CC/iClone, any humanoid):
the bpy side of ``core.scene.bone_map`` (which bone plays which joint) and
``core.scene.rig_retarget`` (the bake). This module only reads the armature into plain arrays,
keeps the editable bone map on the armature object (``Object.shapemove_bone_map``) and writes
the keys (``keyframes.write_pose_action``).

UI: the "Your Rig" panel (target armature, motion, Auto Map / presets, the bone map with a bone
picker per joint, Bake). Headless: ``retarget_rig_file`` (the ``retarget-rig`` command).
"""
from __future__ import annotations

from pathlib import Path

import bpy
import numpy as np
from bpy.props import BoolProperty, CollectionProperty, EnumProperty, PointerProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from ..core.errors import ShapeMoveError
from ..core.scene.bone_map import (SMPL22, ArmatureRest, apply_preset, builtin_presets, check_map, load_preset,
                                   map_armature, save_preset)
from ..core.scene.motion_file import load_motion
from ..core.scene.rig_retarget import retarget_to_armature
from .headless import save_blend
from .keyframes import write_pose_action
from .operators import ReportingOperator
from .panels import _SettingsPanel
from .redecode import MOTION_FILE_KEY
from .rig_state import rig_of

REDECODED_KEY = "shapemove_redecoded_file"


# ---- plain arrays in, keys out ----

def read_armature(obj) -> ArmatureRest:
    """The armature object's rest pose as arrays (bones ordered parents first)."""
    if obj is None or obj.type != "ARMATURE":
        raise ShapeMoveError("pick an armature object as the target rig")
    bones = list(obj.data.bones)
    if not bones:
        raise ShapeMoveError(f"armature {obj.name!r} has no bones")
    depth = {}
    for b in bones:
        d, p = 0, b.parent
        while p is not None:
            d, p = d + 1, p.parent
        depth[b.name] = d
    bones.sort(key=lambda b: depth[b.name])
    index = {b.name: i for i, b in enumerate(bones)}
    mats = np.array([np.array(b.matrix_local, dtype=np.float64) for b in bones])
    return ArmatureRest(
        names=[b.name for b in bones],
        parents=[index[b.parent.name] if b.parent else -1 for b in bones],
        heads=np.array([tuple(b.head_local) for b in bones]), tails=np.array([tuple(b.tail_local) for b in bones]),
        rest_rot=mats[:, :3, :3], deform=[b.use_deform for b in bones],
        matrix_world=np.array(obj.matrix_world, dtype=np.float64))


def stored_map(obj) -> dict:
    """The bone map kept on the armature object (joints left empty are omitted)."""
    return {item.joint: item.bone for item in obj.shapemove_bone_map if item.bone}


def store_map(obj, mapping: dict) -> None:
    """Write a bone map onto the object, one row per SMPL body joint (empty where unmapped)."""
    items = obj.shapemove_bone_map
    items.clear()
    for joint in SMPL22:
        item = items.add()
        item.joint = joint
        item.bone = mapping.get(joint, "")


def auto_map_object(obj, preset=None) -> str:
    """Fill the object's bone map from a preset (name, path or dict) or automatically; returns how."""
    mapping, how = map_armature(read_armature(obj), preset)
    store_map(obj, mapping)
    return f"{len(mapping)} of 22 joints mapped ({how})"


def bake_onto_armature(context, obj, motion, mapping: dict | None = None, plant_feet: bool = True):
    """Bake ``motion`` (a motion_file.Motion) onto ``obj``: a new action keyed on the mapped bones
    (the pelvis bone's location too); scene frame range and rate follow the motion. Returns
    (action, RigBake)."""
    arm = read_armature(obj)
    if mapping is None:
        mapping = stored_map(obj) if len(obj.shapemove_bone_map) else map_armature(arm)[0]
    check_map(mapping, arm.names)
    bake = retarget_to_armature(motion, arm, mapping, plant_feet=plant_feet)
    for pb in obj.pose.bones:  # unmapped bones hold their rest pose
        pb.location = (0.0, 0.0, 0.0)
        pb.rotation_quaternion = (1.0, 0.0, 0.0, 0.0)
        pb.rotation_euler = (0.0, 0.0, 0.0)
        pb.scale = (1.0, 1.0, 1.0)
    name = f"{obj.name}_shapemove" + (f"_{motion.prompt[:40]}" if motion.prompt else "")
    action = write_pose_action(obj, bake.quats, bake.root_offset, motion.fps, bake.bones, name)
    scene = context.scene
    scene.render.fps = int(round(motion.fps))
    scene.render.fps_base = scene.render.fps / float(motion.fps)
    scene.frame_start = 1
    scene.frame_end = max(1, motion.num_frames)
    scene.frame_set(1)
    return action, bake


def motion_file_of(obj) -> str:
    """The motion file behind a ShapeMove rig (its re-decoded motion after a shape change)."""
    rig = rig_of(obj)
    if rig is None:
        return ""
    return str(rig.get(REDECODED_KEY) or rig.get(MOTION_FILE_KEY) or "")


def retarget_rig_file(motion_path, blend_in, armature: str, out_blend, preset=None, plant_feet: bool = True) -> dict:
    """Headless: open ``blend_in``, bake the motion file onto its armature object ``armature``
    (bone map from ``preset``, else the one stored on the object, else automatic), save
    ``out_blend`` atomically. Returns facts about the bake."""
    ensure_registered()
    motion = load_motion(motion_path)
    blend_in = Path(blend_in)
    if not blend_in.is_file():
        raise ShapeMoveError(f".blend file not found: {blend_in}")
    bpy.ops.wm.open_mainfile(filepath=str(blend_in.resolve()))
    obj = bpy.data.objects.get(armature)
    if obj is None or obj.type != "ARMATURE":
        arms = [o.name for o in bpy.data.objects if o.type == "ARMATURE"]
        raise ShapeMoveError(f"{blend_in.name} has no armature object {armature!r} "
                             f"(armatures: {', '.join(arms) or 'none'})")
    if preset is not None or not len(obj.shapemove_bone_map):
        how = auto_map_object(obj, preset)
    else:
        how = "bone map stored on the armature"
    action, bake = bake_onto_armature(bpy.context, obj, motion, stored_map(obj), plant_feet=plant_feet)
    save_blend(Path(out_blend))
    return {"armature": obj.name, "action": action.name, "frames": motion.num_frames, "bones": bake.bones,
            "mapping": how, "scale": bake.scale, "heading_deg": float(np.degrees(bake.heading))}


# ---- properties ----

class ShapeMoveBoneMapItem(bpy.types.PropertyGroup):
    joint: StringProperty(name="Joint", description="SMPL body joint")
    bone: StringProperty(name="Bone", description="The bone of your rig that plays this joint (empty: none)")


def _is_armature(_self, obj):
    return obj.type == "ARMATURE" and rig_of(obj) is None


def _is_shapemove_rig(_self, obj):
    return rig_of(obj) is not None


def _preset_items(_self, _context):
    try:
        shipped = builtin_presets()
    except ShapeMoveError:
        shipped = {}
    items = [("AUTO", "Automatic", "A shipped preset when the names fit, else match the skeleton by its shape")]
    items += [(k, p["name"], p["description"]) for k, p in shipped.items()]
    return items


class ShapeMoveRigSettings(bpy.types.PropertyGroup):
    target: PointerProperty(name="Your rig", type=bpy.types.Object, poll=_is_armature,
                            description="The armature to put the motion on")
    source_rig: PointerProperty(name="ShapeMove rig", type=bpy.types.Object, poll=_is_shapemove_rig,
                                description="Take the motion of this ShapeMove rig (generated or retargeted)")
    motion_path: StringProperty(name="Motion file", subtype="FILE_PATH", default="",
                                description="A ShapeMove motion (.npz); empty: the ShapeMove rig's motion")
    preset: EnumProperty(name="Preset", items=_preset_items)
    plant_feet: BoolProperty(name="Plant feet", default=True,
                             description="Hold each foot still while it rests on the floor (two-bone IK)")
    show_map: BoolProperty(name="Bone map", default=True)


# ---- operators ----

def _target(context):
    obj = context.scene.shapemove_rig.target
    if obj is None:
        active = context.active_object
        obj = active if active is not None and active.type == "ARMATURE" and rig_of(active) is None else None
    if obj is None:
        raise ShapeMoveError("pick your rig (an armature) as the target")
    return obj


class SHAPEMOVE_OT_rig_map_auto(ReportingOperator, bpy.types.Operator):
    """Find which bone of your rig plays which body joint (the chosen preset, or automatic)"""
    bl_idname = "shapemove.rig_map_auto"
    bl_label = "Map Bones"
    bl_options = {"REGISTER", "UNDO"}

    def start(self, context):
        s = context.scene.shapemove_rig
        return auto_map_object(_target(context), None if s.preset == "AUTO" else s.preset)


class SHAPEMOVE_OT_rig_map_load(ReportingOperator, ImportHelper, bpy.types.Operator):
    """Load a bone map preset (.json)"""
    bl_idname = "shapemove.rig_map_load"
    bl_label = "Load Bone Map"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})

    def start(self, context):
        obj = _target(context)
        arm = read_armature(obj)
        preset = load_preset(self.filepath)
        mapping = apply_preset(preset, arm.names)
        store_map(obj, mapping)
        return f"{preset['name']}: {len(mapping)} of 22 joints mapped"


class SHAPEMOVE_OT_rig_map_save(ReportingOperator, ExportHelper, bpy.types.Operator):
    """Save the bone map as a preset (.json) to use on other rigs with these bone names"""
    bl_idname = "shapemove.rig_map_save"
    bl_label = "Save Bone Map"
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})

    def start(self, context):
        obj = _target(context)
        mapping = stored_map(obj)
        if not mapping:
            raise ShapeMoveError("the bone map is empty: map the bones first")
        path = save_preset(self.filepath, mapping, Path(self.filepath).stem, f"saved from {obj.name}")
        return f"saved {len(mapping)} joints to {path}"


class SHAPEMOVE_OT_retarget_rig(ReportingOperator, bpy.types.Operator):
    """Bake the motion onto your rig: a new action on the mapped bones, root motion and height scaled
    to your rig's legs, feet planted"""
    bl_idname = "shapemove.retarget_rig"
    bl_label = "Bake onto Rig"
    bl_options = {"REGISTER", "UNDO"}

    def start(self, context):
        s = context.scene.shapemove_rig
        obj = _target(context)
        path = bpy.path.abspath(s.motion_path) if s.motion_path else motion_file_of(s.source_rig or context.active_object)
        if not path:
            raise ShapeMoveError("pick a motion file or a ShapeMove rig whose motion to use")
        motion = load_motion(path)
        if not len(obj.shapemove_bone_map):
            auto_map_object(obj, None if s.preset == "AUTO" else s.preset)
        action, bake = bake_onto_armature(context, obj, motion, stored_map(obj), plant_feet=s.plant_feet)
        return (f"baked {motion.num_frames} frames onto {obj.name} ({len(bake.bones)} bones, "
                f"scale {bake.scale:.2f}) as action {action.name}")


# ---- panel ----

class SHAPEMOVE_PT_your_rig(_SettingsPanel, bpy.types.Panel):
    bl_label = "Your Rig"
    SETTINGS = "shapemove_rig"

    def draw_settings(self, context, s, col):
        col.prop(s, "target")
        col.prop(s, "source_rig")
        col.prop(s, "motion_path")
        row = col.row(align=True)
        row.prop(s, "preset", text="")
        row.operator("shapemove.rig_map_auto", icon="BONE_DATA")
        row = col.row(align=True)
        row.operator("shapemove.rig_map_load", text="Load", icon="FILEBROWSER")
        row.operator("shapemove.rig_map_save", text="Save", icon="FILE_TICK")
        obj = s.target
        if obj is not None and len(obj.shapemove_bone_map):
            col.prop(s, "show_map", icon="TRIA_DOWN" if s.show_map else "TRIA_RIGHT", emboss=False)
            if s.show_map:
                box = col.box().column(align=True)
                for item in obj.shapemove_bone_map:
                    r = box.row(align=True)
                    r.label(text=item.joint.replace("_", " "))
                    r.prop_search(item, "bone", obj.data, "bones", text="")
        col.prop(s, "plant_feet")
        col.operator("shapemove.retarget_rig", icon="ACTION")


classes = (ShapeMoveBoneMapItem, ShapeMoveRigSettings, SHAPEMOVE_OT_rig_map_auto, SHAPEMOVE_OT_rig_map_load,
           SHAPEMOVE_OT_rig_map_save, SHAPEMOVE_OT_retarget_rig, SHAPEMOVE_PT_your_rig)


def register():
    bpy.types.Object.shapemove_bone_map = CollectionProperty(type=ShapeMoveBoneMapItem)
    bpy.types.Scene.shapemove_rig = PointerProperty(type=ShapeMoveRigSettings)


def ensure_registered() -> None:
    """Register the bone-map property without the whole add-on (headless ``retarget-rig``)."""
    if not hasattr(bpy.types.Object, "shapemove_bone_map"):
        if not hasattr(bpy.types, "ShapeMoveBoneMapItem"):
            bpy.utils.register_class(ShapeMoveBoneMapItem)
        bpy.types.Object.shapemove_bone_map = CollectionProperty(type=ShapeMoveBoneMapItem)


def unregister():
    del bpy.types.Scene.shapemove_rig
    del bpy.types.Object.shapemove_bone_map
