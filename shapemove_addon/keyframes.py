"""Write a whole motion into a new Action in one go (Blender 4.2 LTS .. 5.x).

Keys are written per F-Curve with ``keyframe_points.add(n)`` + ``foreach_set("co", ...)``, which
is tens of times faster than one ``keyframe_insert`` per bone and frame. Blender 4.4 introduced
slotted actions (F-Curves live in a channelbag of a layer/strip for an action slot) and 5.0 removed
the legacy ``Action.fcurves``; both layouts are handled here (checked against bpy 4.2, 4.3, 4.4,
4.5 and 5.0 with ``tools/check_blender_versions.sh``).
"""
from __future__ import annotations

import bpy
import numpy as np

from ..core.errors import ShapeMoveError
from ..core.scene.pose import pose_bone_quaternions, root_locations

FIRST_FRAME = 1


def _fcurve_factory(action, obj):
    """Assign ``action`` to ``obj`` and return ``new(data_path, index, group) -> FCurve``."""
    anim = obj.animation_data or obj.animation_data_create()
    if bpy.app.version >= (4, 4, 0):  # slotted actions
        slot = action.slots.new(id_type="OBJECT", name=obj.name)
        anim.action = action
        if anim.action_slot != slot:
            anim.action_slot = slot
        try:
            from bpy_extras.anim_utils import action_ensure_channelbag_for_slot
        except ImportError:  # 4.4 / 4.5 do not have the helper yet
            layer = action.layers[0] if action.layers else action.layers.new("Layer")
            strip = layer.strips[0] if layer.strips else layer.strips.new(type="KEYFRAME")
            channelbag = strip.channelbag(slot, ensure=True)
        else:
            channelbag = action_ensure_channelbag_for_slot(action, slot)
        groups = {}

        def new(path, index, group):
            # ChannelbagFCurves.new takes group_name only from 5.0: group the curve ourselves
            fc = channelbag.fcurves.new(path, index=index)
            if group not in groups:
                groups[group] = channelbag.groups.get(group) or channelbag.groups.new(group)
            fc.group = groups[group]
            return fc
        return new
    anim.action = action  # Blender 4.2 / 4.3: legacy flat list
    return lambda path, index, group: action.fcurves.new(path, index=index, action_group=group)


def _write_curve(new_fcurve, path, index, group, frames, values, linear):
    fc = new_fcurve(path, index, group)
    points = fc.keyframe_points
    points.add(len(frames))
    co = np.empty(2 * len(frames), dtype=np.float32)
    co[0::2] = frames
    co[1::2] = values
    points.foreach_set("co", co)
    points.foreach_set("interpolation", linear)
    fc.update()
    return fc


def write_pose_action(armature_obj, rotations, transl, fps: float, bone_names, action_name: str):
    """Key every frame of a motion on ``armature_obj``'s pose bones; returns the new Action.

    rotations: (T,J,3,3) local joint rotations (SMPL convention) in the armature's axes, converted
    with each bone's rest matrix, or (T,J,4) pose-bone quaternions (w,x,y,z) written as they are.
    transl: (T,3) armature-space offset of the root (first) bone, keyed as its ``location``.
    fps: the motion's frame rate (stored on the action; the scene's rate is the caller's job).
    bone_names: J names, in the order of the rotations' joint axis; bone_names[0] is the root.
    Frame t of the motion is keyed at scene frame ``FIRST_FRAME + t``, linear interpolation.
    """
    rot = np.asarray(rotations, dtype=np.float64)
    transl = np.asarray(transl, dtype=np.float64)
    names = list(bone_names)
    if rot.ndim not in (3, 4) or rot.shape[1] != len(names) or rot.shape[2:] not in ((3, 3), (4,)):
        raise ShapeMoveError(f"rotations must be (T,{len(names)},3,3) or (T,{len(names)},4), got {rot.shape}")
    T = rot.shape[0]
    if T == 0 or transl.shape != (T, 3):
        raise ShapeMoveError(f"transl must be ({T},3) with at least one frame, got {transl.shape}")
    if armature_obj is None or armature_obj.type != "ARMATURE":
        raise ShapeMoveError("write_pose_action needs an armature object")
    bones = armature_obj.data.bones
    missing = [n for n in names if n not in bones]
    if missing:
        raise ShapeMoveError(f"armature {armature_obj.name!r} has no bones named {', '.join(missing)}")
    rest = np.array([np.array(bones[n].matrix_local, dtype=np.float64)[:3, :3] for n in names])
    quats = pose_bone_quaternions(rot, rest) if rot.shape[2:] == (3, 3) else rot
    locations = root_locations(transl, rest[0])

    for n in names:
        pb = armature_obj.pose.bones[n]
        pb.rotation_mode = "QUATERNION"

    action = bpy.data.actions.new(action_name)
    try:
        action["shapemove_fps"] = float(fps)
        new_fcurve = _fcurve_factory(action, armature_obj)
        frames = FIRST_FRAME + np.arange(T, dtype=np.float64)
        linear = np.full(T, bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value, dtype=np.int32)
        for j, n in enumerate(names):
            path = f'pose.bones["{n}"].rotation_quaternion'
            for c in range(4):
                _write_curve(new_fcurve, path, c, n, frames, quats[:, j, c], linear)
        for c in range(3):
            _write_curve(new_fcurve, f'pose.bones["{names[0]}"].location', c, names[0], frames, locations[:, c], linear)
        action.frame_range = (FIRST_FRAME, FIRST_FRAME + max(T - 1, 1))
        action.use_frame_range = False
    except Exception:
        if armature_obj.animation_data and armature_obj.animation_data.action == action:
            armature_obj.animation_data.action = None
        bpy.data.actions.remove(action)
        raise
    return action


def action_fcurves(action, obj=None):
    """The F-Curves of ``action`` (for ``obj``'s slot when slotted), on any supported Blender."""
    if bpy.app.version >= (4, 4, 0):
        slot = None
        if obj is not None and obj.animation_data and obj.animation_data.action == action:
            slot = obj.animation_data.action_slot
        curves = []
        for layer in action.layers:
            for strip in layer.strips:
                for bag in strip.channelbags:
                    if slot is None or bag.slot == slot:
                        curves.extend(bag.fcurves)
        return curves
    return list(action.fcurves)
