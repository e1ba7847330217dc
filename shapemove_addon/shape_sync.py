"""Keep the skeleton on the body when its shape changes.

The betas of a ShapeMove rig are the values of the body mesh's shape keys "beta_0".."beta_9"
(the single source of truth). ``set_betas`` (used by the panel sliders) writes the keys and calls
``on_betas_changed`` at once. Edits made elsewhere (the Shape Keys list, drivers, Python) are
caught by a depsgraph handler that compares the keys with the betas the bones were placed for
and schedules ``on_betas_changed`` on a timer (bones can only be edited outside the depsgraph
update, in Edit Mode).
"""
from __future__ import annotations

import bpy
import numpy as np
from bpy.app.handlers import persistent

from ..core.constants import NUM_BETAS
from ..core.errors import ShapeMoveError
from ..core.body.body_arrays import rest_joints_for
from . import grounding, redecode
from .bone_placement import place_bones
from .rig_state import body_of, current_betas, placed_betas, rig_of
from .scene_build import RIG_MARK, SLIDER_RANGE

TOLERANCE = 1e-6


def set_betas(rig, betas, context=None) -> None:
    """Write ``betas`` (10,) into the shape keys and move the bones to match."""
    body = body_of(rig)
    if body is None or body.data.shape_keys is None:
        raise ShapeMoveError(f"{rig.name!r} has lost its body mesh or its shape keys")
    keys = body.data.shape_keys.key_blocks
    for i, b in enumerate(np.asarray(betas, dtype=np.float64)):
        kb = keys.get(f"beta_{i}")
        if kb is not None:
            kb.value = float(np.clip(b, -SLIDER_RANGE, SLIDER_RANGE))
    on_betas_changed(rig, context)


def on_betas_changed(obj, context=None) -> None:
    """Hook run whenever a rig's betas change: re-place the bones on the new rest joints.

    The armature's keyed local rotations are kept (rebased onto the new bone frames), so the same
    motion now plays on the new body at once, and the root is moved up or down frame by frame so
    the feet stand on the new body's mesh soles (``grounding``); when the rig has motion tokens, a
    debounced job then re-decodes the motion for the new body (``redecode.schedule``) and
    replaces the keys."""
    rig = rig_of(obj)
    if rig is None:
        return
    context = context or bpy.context
    betas = current_betas(rig)
    jt = np.array(rig["shapemove_joint_template"], dtype=np.float64).reshape(-1, 3)
    jd = np.array(rig["shapemove_joint_shapedirs"], dtype=np.float64).reshape(len(jt), 3, NUM_BETAS)
    names = rig["shapemove_joint_names"].split("\n")
    parents = [int(p) for p in rig["shapemove_parents"]]
    keys = place_bones(context, rig, rest_joints_for(jt, jd, betas), names, parents)
    if keys is not None:  # feet on the floor of the new body's mesh
        grounding.ground_keys(rig, names, placed_betas(rig), betas, keys)
    rig["shapemove_betas"] = betas.tolist()
    context.scene.frame_set(context.scene.frame_current)  # re-evaluate the rebased action
    redecode.schedule(rig)


def stale_rigs(scene) -> list:
    """Rigs in ``scene`` whose shape keys no longer match the betas their bones are placed for."""
    out = []
    for obj in scene.objects:
        if obj.type == "ARMATURE" and obj.get(RIG_MARK) and body_of(obj) is not None:
            if np.abs(current_betas(obj) - placed_betas(obj)).max() > TOLERANCE:
                out.append(obj)
    return out


_pending: set[str] = set()


def _run_pending():
    names = sorted(_pending)
    _pending.clear()
    for name in names:
        rig = bpy.data.objects.get(name)
        if rig is not None:
            try:
                on_betas_changed(rig)
            except Exception as exc:  # never let a timer raise into Blender's main loop
                print(f"ShapeMove: could not move the bones of {name}: {exc}")
    return None


@persistent
def depsgraph_handler(scene, depsgraph=None):
    # only shape-key edits can change betas; skip the scan for every other update
    if depsgraph is not None and not any(isinstance(u.id, bpy.types.Key) for u in depsgraph.updates):
        return
    for rig in stale_rigs(scene):
        if rig.name not in _pending:
            _pending.add(rig.name)
            if not bpy.app.timers.is_registered(_run_pending):
                bpy.app.timers.register(_run_pending, first_interval=0.0)


def register():
    if depsgraph_handler not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(depsgraph_handler)


def unregister():
    if depsgraph_handler in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(depsgraph_handler)
    if bpy.app.timers.is_registered(_run_pending):
        bpy.app.timers.unregister(_run_pending)
    _pending.clear()
    redecode.unregister()
