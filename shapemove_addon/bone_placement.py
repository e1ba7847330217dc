"""Create or move the 24 bones of a ShapeMove armature so they sit on the body's rest joints.

Edit bones exist only in Edit Mode, so the armature is switched to Edit Mode for the change and
back afterwards (the previous mode and active object are restored). When bones move, the pose
keys of the rig's action are re-expressed against the new bone rest frames, so the local joint
rotations of the motion stay exactly what they were.
"""
from __future__ import annotations

import contextlib

import bpy
import numpy as np

from ..core.errors import ShapeMoveError
from ..core.scene.bones import bone_layout
from ..core.scene.pose import rebase_locations, rebase_quaternions
from .keyframes import action_fcurves


@contextlib.contextmanager
def edit_bones_of(context, arm_obj):
    """Yield ``arm_obj.data.edit_bones`` with the armature in Edit Mode; restore mode and active."""
    if context.mode not in ("OBJECT", "POSE", "EDIT_ARMATURE"):
        raise ShapeMoveError("switch to Object Mode or Pose Mode first")
    view_layer = context.view_layer
    if view_layer.objects.get(arm_obj.name) is None:
        raise ShapeMoveError(f"armature {arm_obj.name!r} is not in the current view layer")
    prev_active = view_layer.objects.active
    prev_mode = arm_obj.mode
    override = dict(active_object=arm_obj, object=arm_obj, selected_objects=[arm_obj],
                    selected_editable_objects=[arm_obj], edit_object=arm_obj)
    view_layer.objects.active = arm_obj
    try:
        with context.temp_override(**override):
            if arm_obj.mode != "EDIT":
                try:
                    bpy.ops.object.mode_set(mode="EDIT")
                except RuntimeError as exc:  # hidden, linked from a library, ...
                    raise ShapeMoveError(f"cannot edit the bones of {arm_obj.name!r}: {exc}".strip()) from None
        yield arm_obj.data.edit_bones
    finally:
        with context.temp_override(**override):
            if arm_obj.mode != prev_mode:
                bpy.ops.object.mode_set(mode=prev_mode)
        if prev_active is not None and view_layer.objects.get(prev_active.name) is not None:
            view_layer.objects.active = prev_active


def rest_rotations(arm_obj, names) -> np.ndarray:
    """(J,3,3) rotation part of each bone's ``matrix_local`` (armature space rest frame)."""
    return np.array([np.array(arm_obj.data.bones[n].matrix_local, dtype=np.float64)[:3, :3] for n in names])


def place_bones(context, arm_obj, rest_joints, names, parents) -> None:
    """Put bone ``names[j]`` on ``rest_joints[j]`` (J,3, armature space, Z-up), creating the
    bones on first use; keyed rotations are rebased so the motion is unchanged."""
    layout = bone_layout(rest_joints, parents)
    existing = all(n in arm_obj.data.bones for n in names)
    old = rest_rotations(arm_obj, names) if existing else None
    with edit_bones_of(context, arm_obj) as ebones:
        for j, n in enumerate(names):
            eb = ebones.get(n) or ebones.new(n)
            eb.head = layout.heads[j].tolist()
            eb.tail = layout.tails[j].tolist()
            eb.roll = float(layout.rolls[j])
            eb.use_connect = False
            eb.use_deform = True
        for j, n in enumerate(names):
            ebones[n].parent = ebones[names[parents[j]]] if parents[j] >= 0 else None
    if old is not None:
        _rebase_action(arm_obj, names, old, rest_rotations(arm_obj, names))


def _rebase_action(arm_obj, names, old, new) -> None:
    anim = arm_obj.animation_data
    if anim is None or anim.action is None:
        return
    curves = {(fc.data_path, fc.array_index): fc for fc in action_fcurves(anim.action, arm_obj)}

    def read(path, size):
        fcs = [curves.get((path, i)) for i in range(size)]
        if any(fc is None for fc in fcs) or len({len(fc.keyframe_points) for fc in fcs}) != 1:
            return None, None
        cos = []
        for fc in fcs:
            co = np.empty(2 * len(fc.keyframe_points), dtype=np.float32)
            fc.keyframe_points.foreach_get("co", co)
            cos.append(co.reshape(-1, 2))
        return fcs, cos

    def write(fcs, cos, values):
        for fc, co, v in zip(fcs, cos, values.T):
            co[:, 1] = v
            fc.keyframe_points.foreach_set("co", co.ravel())
            fc.update()

    for j, n in enumerate(names):
        fcs, cos = read(f'pose.bones["{n}"].rotation_quaternion', 4)
        if fcs:
            write(fcs, cos, rebase_quaternions(np.stack([c[:, 1] for c in cos], -1), old[j], new[j]))
    fcs, cos = read(f'pose.bones["{names[0]}"].location', 3)
    if fcs:
        write(fcs, cos, rebase_locations(np.stack([c[:, 1] for c in cos], -1), old[0], new[0]))
