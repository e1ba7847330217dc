"""Build the ShapeMove rig for a motion in one step: body mesh + armature + modifier + action.

Result (all new datablocks, linked to ``collection``):
- armature object "<name>" (identity transform) with 24 bones named after the SMPL joints, heads on
  the body's rest joints for the motion's betas, and an action keying every frame;
- mesh object "<name>_body", child of the armature, with shape keys "Basis" + "beta_0".."beta_9"
  (slider range -5..5, key value = beta), one vertex group of LBS weights per joint and an
  Armature modifier.
Axes: the Y-up data is rotated into Blender's Z-up inside the mesh/armature data (see
``core.scene.axes``), so both objects keep identity transforms.

Nothing else in the file is changed except the scene's frame range and frame rate. If anything
fails, every datablock created so far is removed and the error is raised again.
"""
from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np

from ..core.scene.motion_file import Motion
from ..core.scene.rig_data import RigData, motion_channels_z_up, rig_data
from .bone_placement import place_bones
from .keyframes import FIRST_FRAME, write_pose_action

SLIDER_RANGE = 5.0
RIG_MARK = "shapemove_rig"


@dataclass
class BuiltRig:
    armature: bpy.types.Object
    body: bpy.types.Object
    action: bpy.types.Action


def build_rig(context, motion: Motion, body_model, name: str = "ShapeMove", collection=None) -> BuiltRig:
    """motion: a validated Motion; body_model: the BodyModel it was made for."""
    data = rig_data(body_model, motion.betas)
    rotations, transl = motion_channels_z_up(motion.poses, motion.transl)
    collection = collection or context.scene.collection
    created: list = []  # (collection in bpy.data, datablock), removed in reverse on failure
    try:
        arm_data = bpy.data.armatures.new(name)
        created.append((bpy.data.armatures, arm_data))
        arm_obj = bpy.data.objects.new(name, arm_data)
        created.append((bpy.data.objects, arm_obj))
        collection.objects.link(arm_obj)
        arm_data.display_type = "OCTAHEDRAL"
        arm_obj.show_in_front = True
        _store_shape_space(arm_obj, data)

        mesh = _body_mesh(f"{name}_body", data)
        created.append((bpy.data.meshes, mesh))
        body_obj = bpy.data.objects.new(f"{name}_body", mesh)
        created.append((bpy.data.objects, body_obj))
        collection.objects.link(body_obj)
        _add_shape_keys(body_obj, data)
        _add_vertex_groups(body_obj, data)
        body_obj.parent = arm_obj
        mod = body_obj.modifiers.new("Armature", "ARMATURE")
        mod.object = arm_obj
        mod.use_vertex_groups = True
        arm_obj["shapemove_body"] = body_obj

        place_bones(context, arm_obj, data.bones.heads, data.joint_names, data.parents)
        action = write_pose_action(arm_obj, rotations, transl, motion.fps, data.joint_names, f"{name}_motion")
        created.append((bpy.data.actions, action))
        if motion.prompt:
            arm_obj["shapemove_prompt"] = motion.prompt
        _set_scene_timing(context.scene, motion.num_frames, motion.fps)
    except BaseException:
        for store, block in reversed(created):
            if store.get(block.name) == block:
                if isinstance(block, bpy.types.Object) and block.type == "MESH" and block.data.shape_keys:
                    block.shape_key_clear()  # the Key datablock goes with it
                store.remove(block)
        raise
    return BuiltRig(arm_obj, body_obj, action)


def _store_shape_space(arm_obj, data: RigData) -> None:
    """What the rig needs to re-place its bones for new betas, without the body model."""
    arm_obj[RIG_MARK] = 1
    arm_obj["shapemove_body_model"] = data.body_model
    arm_obj["shapemove_joint_template"] = data.joint_template.ravel().tolist()
    arm_obj["shapemove_joint_shapedirs"] = data.joint_shapedirs.ravel().tolist()
    arm_obj["shapemove_parents"] = [int(p) for p in data.parents]
    arm_obj["shapemove_joint_names"] = "\n".join(data.joint_names)
    arm_obj["shapemove_betas"] = data.betas.tolist()  # betas the bones are placed for


def _body_mesh(name: str, data: RigData) -> bpy.types.Mesh:
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(data.v_template.astype(np.float32), [], data.faces.astype(np.int32))
    mesh.update()
    if hasattr(mesh, "shade_smooth"):  # 4.1+
        mesh.shade_smooth()
    return mesh


def _add_shape_keys(obj, data: RigData) -> None:
    obj.shape_key_add(name="Basis", from_mix=False)
    for i, coords in enumerate(data.key_coords):
        kb = obj.shape_key_add(name=f"beta_{i}", from_mix=False)
        kb.data.foreach_set("co", coords.astype(np.float32).ravel())
        kb.slider_min, kb.slider_max = -SLIDER_RANGE, SLIDER_RANGE
        kb.value = float(np.clip(data.betas[i], -SLIDER_RANGE, SLIDER_RANGE))
    obj.data.shape_keys.use_relative = True


def _add_vertex_groups(obj, data: RigData) -> None:
    w = data.skin_weights
    for j, joint in enumerate(data.joint_names):
        vg = obj.vertex_groups.new(name=joint)
        col = w[:, j]
        idx = np.nonzero(col > 0)[0]
        values = col[idx]
        order = np.argsort(values, kind="stable")
        idx, values = idx[order], values[order]
        # one call per distinct weight value (rigid regions share weight 1.0)
        cuts = np.nonzero(np.diff(values))[0] + 1
        for chunk_idx, chunk_val in zip(np.split(idx, cuts), np.split(values, cuts)):
            if len(chunk_idx):
                vg.add(chunk_idx.tolist(), float(chunk_val[0]), "REPLACE")


def _set_scene_timing(scene, num_frames: int, fps: float) -> None:
    fps_int = max(1, int(round(fps)))
    scene.render.fps = fps_int
    scene.render.fps_base = fps_int / float(fps)
    scene.frame_start = FIRST_FRAME
    scene.frame_end = FIRST_FRAME + num_frames - 1
    if not scene.frame_start <= scene.frame_current <= scene.frame_end:
        scene.frame_current = FIRST_FRAME
