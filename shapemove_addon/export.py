"""Export a ShapeMove rig (armature + body, with its animation) as FBX, glTF (.glb) or BVH.

Each file reads back through Blender's own importer with its default settings at the same bone and
mesh positions (tests/test_blender_export.py):
- glTF: Blender's exporter with every skin influence (not only the 4 largest) and the rig's
  action sampled per frame, at Blender's glTF times (frame f at f / fps, which its importer reads
  back at frame f).
- FBX: Blender's exporter, Y up, "FBX_SCALE_ALL" (1 unit = 1 m in the file's UnitScaleFactor,
  objects at scale 1, no 100x root nodes), so game engines import it at the right size; the
  action is written from time 0 (Blender's FBX exporter writes absolute frame times, and its
  importer adds one frame, so the keys are moved to frame 0 for the export and back afterwards).
- BVH: ``bvh_writer`` (Y up, centimetres, world-aligned rest frames), not Blender's exporter,
  which writes Z-up armature axes.
A rig animated by NLA strips only (a timeline of prompts, possibly re-timed) is baked frame by
frame into a temporary action for the export (``_nla_baked``), removed afterwards. The root
motion mode (pelvis, object, root bone, in place: ``animation_rig``) is in the rig's keys, so
every format carries it (BVH: the armature's bones only, not the object's travel).
The exporters see only the rig (selection overridden) and write to a temporary name first,
renamed when complete (atomic). Selection, the active object and the mode are restored afterwards.
"""
from __future__ import annotations

import contextlib
import os
from pathlib import Path

import bpy
import numpy as np

from ..core.errors import ShapeMoveError
from .bvh_writer import write_bvh
from .keyframes import action_fcurves
from .rig_state import body_of, rig_of

FORMATS = {"FBX": ".fbx", "GLTF": ".glb", "BVH": ".bvh"}


@contextlib.contextmanager
def _only_selected(context, objects, active):
    view_layer = context.view_layer
    before = [o for o in view_layer.objects if o.select_get()]
    prev_active = view_layer.objects.active
    try:
        for o in before:
            o.select_set(False)
        for o in objects:
            o.select_set(True)
        view_layer.objects.active = active
        with context.temp_override(active_object=active, object=active, selected_objects=list(objects),
                                   selected_editable_objects=list(objects)):
            yield
    finally:
        for o in view_layer.objects:
            o.select_set(o in before)
        view_layer.objects.active = prev_active


@contextlib.contextmanager
def _action_from_frame_zero(rig, scene, start: int, end: int):
    """Move the rig's keys by -start and the scene range to [0, end - start] while exporting."""
    anim = rig.animation_data
    curves = action_fcurves(anim.action, rig) if anim is not None and anim.action is not None else []
    saved = (scene.frame_start, scene.frame_end, scene.frame_current)

    def shift(delta):
        for fc in curves:
            points = fc.keyframe_points
            for attr in ("co", "handle_left", "handle_right"):
                co = np.empty(2 * len(points), dtype=np.float32)
                points.foreach_get(attr, co)
                co[0::2] += delta
                points.foreach_set(attr, co)
            fc.update()
    shift(-start)
    try:
        scene.frame_start, scene.frame_end = 0, end - start
        yield
    finally:
        shift(start)
        scene.frame_start, scene.frame_end = saved[0], saved[1]
        scene.frame_set(saved[2])


@contextlib.contextmanager
def _nla_baked(rig, scene, start: int, end: int):
    """While exporting: a rig played by NLA strips only gets a temporary action with its evaluated
    pose (every bone's quaternion and location, the object's location) keyed on every frame."""
    anim = rig.animation_data
    if anim is None or anim.action is not None or not any(len(t.strips) for t in anim.nla_tracks):
        yield
        return
    from .animation_rig import _curve_adder, _key_vectors
    from .keyframes import FIRST_FRAME

    names = [pb.name for pb in rig.pose.bones]
    frames = list(range(start, end + 1))
    quats = np.zeros((len(frames), len(names), 4))
    locs = np.zeros((len(frames), len(names), 3))
    obj_loc = np.zeros((len(frames), 3))
    saved = scene.frame_current
    for i, f in enumerate(frames):
        scene.frame_set(f)
        for j, n in enumerate(names):
            pb = rig.pose.bones[n]
            quats[i, j], locs[i, j] = pb.rotation_quaternion, pb.location
        obj_loc[i] = rig.location
    for j in range(len(names)):   # quaternion signs continuous over time
        flip = np.cumsum(np.r_[0, (np.einsum("tc,tc->t", quats[1:, j], quats[:-1, j]) < 0)]) % 2 == 1
        quats[flip, j] *= -1
    action = bpy.data.actions.new(f"{rig.name}_baked")
    try:
        if bpy.app.version >= (4, 4, 0):
            slot = action.slots.new(id_type="OBJECT", name=rig.name)
            anim.action = action
            if anim.action_slot != slot:
                anim.action_slot = slot
        else:
            anim.action = action
        new = _curve_adder(action, rig)
        shift = start - FIRST_FRAME   # _key_vectors keys from FIRST_FRAME
        for j, n in enumerate(names):
            _key_vectors(new, f'pose.bones["{n}"].rotation_quaternion', quats[:, j])
            _key_vectors(new, f'pose.bones["{n}"].location', locs[:, j])
        _key_vectors(new, "location", obj_loc)
        if shift:
            for fc in action_fcurves(action, rig):
                co = np.empty(2 * len(fc.keyframe_points), np.float32)
                fc.keyframe_points.foreach_get("co", co)
                co[0::2] += shift
                fc.keyframe_points.foreach_set("co", co)
                fc.update()
        yield
    finally:
        anim.action = None
        bpy.data.actions.remove(action)
        scene.frame_set(saved)


def _frame_range(rig, scene) -> tuple[int, int]:
    anim = rig.animation_data
    if anim is not None and anim.action is not None:
        lo, hi = anim.action.frame_range
        return int(round(lo)), int(round(hi))
    return scene.frame_start, scene.frame_end


def export_rig(context, rig, filepath, fmt: str = "FBX") -> Path:
    """Write ``rig`` (a ShapeMove armature or its body) to ``filepath`` in ``fmt`` (FBX, GLTF, BVH)."""
    fmt = fmt.upper()
    if fmt not in FORMATS:
        raise ShapeMoveError(f"unknown export format {fmt!r}; use one of {', '.join(FORMATS)}")
    rig = rig_of(rig)
    if rig is None:
        raise ShapeMoveError("select a ShapeMove rig (its armature or body) to export")
    if context.mode != "OBJECT":
        raise ShapeMoveError("switch to Object Mode to export")
    path = Path(bpy.path.abspath(str(filepath)))
    if path.suffix.lower() != FORMATS[fmt]:
        path = path.with_suffix(FORMATS[fmt])
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.stem + ".tmp" + path.suffix)
    body = body_of(rig)
    objects = [rig] + ([body] if body is not None and fmt != "BVH" else [])
    start, end = _frame_range(rig, context.scene)
    try:
        with _only_selected(context, objects, rig):
            if fmt == "FBX":
                with _nla_baked(rig, context.scene, start, end), _action_from_frame_zero(rig, context.scene, start, end):
                    result = bpy.ops.export_scene.fbx(
                        filepath=str(tmp), use_selection=True, object_types={"ARMATURE", "MESH"},
                        add_leaf_bones=False, apply_unit_scale=True, apply_scale_options="FBX_SCALE_ALL",
                        axis_forward="-Z", axis_up="Y", bake_space_transform=False,
                        bake_anim=True, bake_anim_use_all_actions=False, bake_anim_use_nla_strips=False,
                        bake_anim_force_startend_keying=True, bake_anim_simplify_factor=0.0,
                        use_armature_deform_only=True)
            elif fmt == "GLTF":
                with _nla_baked(rig, context.scene, start, end):
                    result = bpy.ops.export_scene.gltf(
                        filepath=str(tmp), export_format="GLB", use_selection=True, export_animations=True,
                        export_skins=True, export_all_influences=True, export_morph=True,
                        export_animation_mode="ACTIVE_ACTIONS", export_force_sampling=True, export_frame_range=False)
            else:
                with _nla_baked(rig, context.scene, start, end):
                    write_bvh(context.scene, rig, tmp, start, end)
                result = {"FINISHED"}
    except (RuntimeError, OSError) as exc:
        tmp.unlink(missing_ok=True)
        raise ShapeMoveError(f"{fmt} export of {rig.name!r} failed: {str(exc).strip()}") from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    if "FINISHED" not in result or not tmp.is_file():
        tmp.unlink(missing_ok=True)
        raise ShapeMoveError(f"{fmt} export of {rig.name!r} wrote nothing")
    os.replace(tmp, path)
    return path
