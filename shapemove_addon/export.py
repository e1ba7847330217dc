"""Export a ShapeMove rig (armature + body, with its animation) as FBX, glTF (.glb) or BVH.

The exporters bundled with Blender do the work; they see only the rig (selection overridden) and
write to a temporary name first, renamed when complete (atomic). Selection, the active object and
the mode are restored afterwards.
"""
from __future__ import annotations

import contextlib
import os
from pathlib import Path

import bpy

from ..core.errors import ShapeMoveError
from .shape_sync import body_of, rig_of

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
                result = bpy.ops.export_scene.fbx(
                    filepath=str(tmp), use_selection=True, object_types={"ARMATURE", "MESH"}, add_leaf_bones=False,
                    bake_anim=True, bake_anim_use_all_actions=False, bake_anim_use_nla_strips=False,
                    bake_anim_force_startend_keying=True, bake_anim_simplify_factor=0.0, use_armature_deform_only=True)
            elif fmt == "GLTF":
                result = bpy.ops.export_scene.gltf(
                    filepath=str(tmp), export_format="GLB", use_selection=True, export_animations=True,
                    export_skins=True, export_morph=True, export_animation_mode="ACTIVE_ACTIONS",
                    export_force_sampling=True, export_frame_range=False)
            else:
                result = bpy.ops.export_anim.bvh(filepath=str(tmp), frame_start=start, frame_end=end,
                                                 rotate_mode="NATIVE", root_transform_only=True)
    except RuntimeError as exc:
        tmp.unlink(missing_ok=True)
        raise ShapeMoveError(f"{fmt} export of {rig.name!r} failed: {str(exc).strip()}") from None
    if "FINISHED" not in result or not tmp.is_file():
        tmp.unlink(missing_ok=True)
        raise ShapeMoveError(f"{fmt} export of {rig.name!r} wrote nothing")
    os.replace(tmp, path)
    return path
