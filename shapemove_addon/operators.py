"""Operators: build the rig from a motion file (.npz)."""
from __future__ import annotations

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ImportHelper

from ..core.errors import ShapeMoveError
from ..core.scene.bodies import load_body
from ..core.scene.motion_file import load_motion
from .scene_build import build_rig


class SHAPEMOVE_OT_build_from_motion(bpy.types.Operator, ImportHelper):
    """Build a shaped, rigged and keyframed body from a ShapeMove motion file (.npz)"""

    bl_idname = "shapemove.build_from_motion"
    bl_label = "Build from Motion File"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".npz"
    filter_glob: StringProperty(default="*.npz", options={"HIDDEN"})
    rig_name: StringProperty(name="Name", default="ShapeMove")
    body_model_file: StringProperty(
        name="Body Model File", subtype="FILE_PATH", default="",
        description="Only for motions made for an SMPL-family body: your SMPL/SMPL-H/SMPL-X model file",
    )

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def execute(self, context):
        try:
            motion = load_motion(self.filepath)
            rig = build_rig(context, motion, load_body(motion.body_model, self.body_model_file or None), name=self.rig_name,
                            collection=context.collection)
        except ShapeMoveError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        for obj in context.view_layer.objects:
            obj.select_set(False)
        rig.armature.select_set(True)
        context.view_layer.objects.active = rig.armature
        self.report({"INFO"}, f"built {rig.armature.name}: {motion.num_frames} frames at {motion.fps:g} fps")
        return {"FINISHED"}


classes = (SHAPEMOVE_OT_build_from_motion,)
