"""Rigs for the animation features (docs/animation.md): loops that cycle, root motion on the
pelvis / the armature object / a root bone / none, and a timeline as NLA strips.

``build_animated_rig`` builds the usual rig (``scene_build.build_rig``) from the channels that
``core.scene.root_motion.rig_channels`` splits off, then
- keys the travel on the armature object (``OBJECT``) or on a new ``root`` bone, the pelvis's
  parent, at the origin with an identity rest frame (``ROOT_BONE``);
- for a loop: one key more (frame 0 moved by the advance) and a Cycles modifier on every F-Curve,
  "Repeat with Offset" on translations and "Repeat" on rotations, so the action repeats for ever
  with the root advancing per cycle;
- for a timeline (``segment_bounds``): one NLA track "ShapeMove timeline" with one strip per
  prompt, each playing its frames of the one action; strips can be moved and scaled.
Keys are written per F-Curve with ``keyframe_points.add(n)`` + ``foreach_set``. A failure removes
everything created, so the scene stays as it was.
"""
from __future__ import annotations

import dataclasses
import json

import bpy
import numpy as np

from ..core.errors import ShapeMoveError
from ..core.scene.axes import points_to_z_up
from ..core.scene.root_motion import ROOT_BONE, rig_channels
from .bone_placement import edit_bones_of
from .keyframes import FIRST_FRAME, action_fcurves
from .scene_build import BuiltRig, build_rig

ROOT_MOTION_KEY = "shapemove_root_motion"
LOOP_KEY = "shapemove_loop_frames"
SEGMENTS_KEY = "shapemove_segments"
TRACK_NAME = "ShapeMove timeline"
PREVIEW_CYCLES = 2   # a loop's scene range shows this many cycles
ROOT_MOTION_ITEMS = (
    ("PELVIS", "Pelvis", "The pelvis bone carries the travel (as generated)"),
    ("OBJECT", "Object", "The armature object carries the horizontal travel; the pelvis stays over the start"),
    ("ROOT_BONE", "Root Bone", "A 'root' bone at the origin, the pelvis's parent, carries the horizontal travel"),
    ("NONE", "In Place", "No horizontal travel (facing and height kept)"),
)


def _curve_adder(action, obj):
    """``new(data_path, index) -> FCurve`` in ``obj``'s slot of ``action`` (any Blender 4.2..5.x)."""
    if bpy.app.version >= (4, 4, 0):
        slot = obj.animation_data.action_slot
        try:
            from bpy_extras.anim_utils import action_ensure_channelbag_for_slot
        except ImportError:
            bag = action.layers[0].strips[0].channelbag(slot, ensure=True)
        else:
            bag = action_ensure_channelbag_for_slot(action, slot)
        return lambda path, index: bag.fcurves.new(path, index=index)
    return lambda path, index: action.fcurves.new(path, index=index)


def _key_vectors(new_curve, path: str, values: np.ndarray) -> None:
    frames = FIRST_FRAME + np.arange(len(values), dtype=np.float64)
    linear = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value
    for c in range(values.shape[1]):
        fc = new_curve(path, c)
        pts = fc.keyframe_points
        pts.add(len(frames))
        co = np.empty(2 * len(frames), np.float32)
        co[0::2], co[1::2] = frames, values[:, c]
        pts.foreach_set("co", co)
        pts.foreach_set("interpolation", np.full(len(frames), linear, np.int32))
        fc.update()


def _add_root_bone(context, arm, pelvis: str) -> None:
    with edit_bones_of(context, arm) as bones:
        root = bones.new(ROOT_BONE)
        root.head, root.tail, root.roll = (0.0, 0.0, 0.0), (0.0, 0.2, 0.0), 0.0   # identity rest frame
        root.use_deform = True   # kept by exporters that write deforming bones only (no vertex group)
        bones[pelvis].parent = root
        bones[pelvis].use_connect = False
    arm.pose.bones[ROOT_BONE].rotation_mode = "QUATERNION"


ROTATION_PATHS = ("rotation_quaternion", "rotation_euler", "rotation_axis_angle")


def _make_cycles(action, obj) -> None:
    """A Cycles modifier on every F-Curve: translations repeat with their per-cycle offset (the
    root advances), rotations repeat as they are. A rotation's closing key is its first rotation,
    but continuous quaternion keys can end it as -q where they began at q (the same rotation, a
    bone that turned past half a circle over the cycle): offset, every later cycle would add -2q."""
    for fc in action_fcurves(action, obj):
        mod = fc.modifiers.new("CYCLES")
        mod.mode_before = mod.mode_after = "REPEAT" if fc.data_path.endswith(ROTATION_PATHS) else "REPEAT_OFFSET"


def cycle_action(arm, action, cycle: int) -> None:
    """Make ``action`` (keyed for one cycle of ``cycle`` frames and its closing key) repeat: its
    F-Curves' Cycles modifiers (``_make_cycles``), its frame range, the rig's loop length."""
    _make_cycles(action, arm)
    arm[LOOP_KEY] = int(cycle)
    action.frame_range = (FIRST_FRAME, FIRST_FRAME + cycle)


def replay_strips(arm, action) -> bool:
    """Point a timeline rig's strips at ``action`` (its motion decoded again for a new body: the same
    frames), each strip keeping its timing (a strip the user moved or scaled stays where it is), and
    let the strips play it rather than the active action. False for a rig without a timeline."""
    anim = arm.animation_data
    track = anim.nla_tracks.get(TRACK_NAME) if anim is not None else None
    if track is None:
        return False
    slot = getattr(anim, "action_slot", None)
    for strip in track.strips:
        keep = (strip.action_frame_start, strip.action_frame_end, strip.scale, strip.repeat, strip.frame_start,
                strip.frame_end)
        strip.action = action
        if slot is not None and hasattr(strip, "action_slot"):
            strip.action_slot = slot
        strip.action_frame_start, strip.action_frame_end, strip.scale, strip.repeat = keep[:4]
        strip.frame_start, strip.frame_end = keep[4:]
    anim.action = None
    return True


def _add_strips(arm, action, motion) -> list:
    anim = arm.animation_data
    slot = getattr(anim, "action_slot", None)
    track = anim.nla_tracks.new()
    track.name = TRACK_NAME
    strips = []
    for prompt, (s, e) in zip(motion.segment_prompts, np.asarray(motion.segment_bounds)):
        strip = track.strips.new(prompt[:60] or "segment", int(FIRST_FRAME + s), action)
        if slot is not None and hasattr(strip, "action_slot"):
            strip.action_slot = slot
        strip.action_frame_start, strip.action_frame_end = float(FIRST_FRAME + s), float(FIRST_FRAME + e)
        strip.frame_start, strip.frame_end = float(FIRST_FRAME + s), float(FIRST_FRAME + e)
        strip.blend_type = "REPLACE"
        strip.extrapolation = "NOTHING" if strips else "HOLD_FORWARD"
        strips.append(strip)
    anim.action = None   # the strips play the action now
    arm[SEGMENTS_KEY] = json.dumps([{"prompt": p, "start": int(s), "end": int(e)}
                                    for p, (s, e) in zip(motion.segment_prompts, np.asarray(motion.segment_bounds))])
    return strips


def key_travel(context, arm, action, travel, root_motion: str) -> None:
    """Key ``travel`` ((T,3) Y up, ``rig_channels``' split-off travel; None: nothing to key) in
    ``action`` on what carries it: the armature object (``OBJECT``) or its root bone (``ROOT_BONE``,
    added as the pelvis's parent when the rig has none yet)."""
    if travel is None:
        return
    new_curve = _curve_adder(action, arm)
    if root_motion.upper() == "OBJECT":
        _key_vectors(new_curve, "location", points_to_z_up(travel))
        return
    if ROOT_BONE not in arm.data.bones:
        _add_root_bone(context, arm, arm["shapemove_joint_names"].split("\n")[0])
    _key_vectors(new_curve, f'pose.bones["{ROOT_BONE}"].location', points_to_z_up(travel))


def build_animated_rig(context, motion, body_model, name: str = "ShapeMove", collection=None,
                       root_motion: str = "PELVIS") -> BuiltRig:
    """The rig for ``motion`` with its loop, root-motion mode and timeline (see the module doc)."""
    ch = rig_channels(motion, root_motion)
    if ch.cycle is not None and motion.segment_bounds is not None:
        raise ShapeMoveError("a motion cannot be both a loop and a timeline of prompts")
    n = len(ch.poses)
    flat = dataclasses.replace(motion, poses=ch.poses, transl=ch.transl, joints=np.zeros((n, 22, 3), np.float32),
                               network_joints=None, contacts=None, features=None, loop_advance=None,
                               segment_bounds=None, segment_prompts=None)
    rig = build_rig(context, flat, body_model, name=name, collection=collection)
    arm = rig.armature
    try:
        key_travel(context, arm, rig.action, ch.travel, root_motion)
        arm[ROOT_MOTION_KEY] = root_motion.upper()
        scene = context.scene
        if ch.cycle is not None:
            cycle_action(arm, rig.action, ch.cycle)
            scene.frame_end = FIRST_FRAME + PREVIEW_CYCLES * ch.cycle - 1
        if motion.segment_bounds is not None:
            _add_strips(arm, rig.action, motion)
    except BaseException:
        remove_rig(rig)
        raise
    return rig


def remove_rig(rig: BuiltRig) -> None:
    """Remove a rig's objects, data and action (a failed build leaves nothing behind)."""
    for obj, store in ((rig.body, bpy.data.meshes), (rig.armature, bpy.data.armatures)):
        data = obj.data
        if obj.type == "MESH" and data.shape_keys:
            obj.shape_key_clear()
        bpy.data.objects.remove(obj)
        if data.users == 0:
            store.remove(data)
    if rig.action is not None and rig.action.users == 0:
        bpy.data.actions.remove(rig.action)
