"""Sidebar panels (View3D > Sidebar > ShapeMove)."""
from __future__ import annotations

import bpy

from .shape_sync import NUM_BETAS, rig_of


class SHAPEMOVE_PT_main(bpy.types.Panel):
    bl_label = "ShapeMove"
    bl_idname = "SHAPEMOVE_PT_main"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "ShapeMove"

    def draw(self, context):
        self.layout.operator("shapemove.build_from_motion", icon="ARMATURE_DATA")


class SHAPEMOVE_PT_shape(bpy.types.Panel):
    bl_label = "Shape"
    bl_idname = "SHAPEMOVE_PT_shape"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "ShapeMove"
    bl_parent_id = "SHAPEMOVE_PT_main"

    @classmethod
    def poll(cls, context):
        return rig_of(context.active_object) is not None

    def draw(self, context):
        rig = rig_of(context.active_object)
        col = self.layout.column(align=True)
        for i in range(NUM_BETAS):
            col.prop(rig.shapemove, "betas", index=i, text=f"Beta {i}", slider=True)


classes = (SHAPEMOVE_PT_main, SHAPEMOVE_PT_shape)
