"""Properties ShapeMove adds to Blender data: ``Object.shapemove``.

``betas`` is a view, not a copy: reading it returns the rig's shape-key values and writing it sets
the keys and moves the bones (``shape_sync.set_betas``), so the sliders and the Shape Keys list can
never disagree.
"""
from __future__ import annotations

import bpy
from bpy.props import FloatVectorProperty

from . import shape_sync


def _get_betas(self):
    rig = shape_sync.rig_of(self.id_data)
    return [float(b) for b in shape_sync.current_betas(rig)] if rig else [0.0] * shape_sync.NUM_BETAS


def _set_betas(self, values):
    rig = shape_sync.rig_of(self.id_data)
    if rig is None:
        return
    try:
        shape_sync.set_betas(rig, values, bpy.context)
    except Exception as exc:  # a setter cannot report; keep the UI alive
        print(f"ShapeMove: could not apply the shape: {exc}")


class ShapeMoveObjectProperties(bpy.types.PropertyGroup):
    betas: FloatVectorProperty(
        name="Betas", description="Body shape (the body's shape keys beta_0..beta_9); bones follow",
        size=shape_sync.NUM_BETAS, min=-5.0, max=5.0, soft_min=-5.0, soft_max=5.0, precision=3,
        get=_get_betas, set=_set_betas,
    )


classes = (ShapeMoveObjectProperties,)


def register():
    bpy.types.Object.shapemove = bpy.props.PointerProperty(type=ShapeMoveObjectProperties)


def unregister():
    del bpy.types.Object.shapemove
