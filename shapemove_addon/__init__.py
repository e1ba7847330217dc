"""The Blender side of ShapeMove (imports bpy): UI, operators and scene building.

``register``/``unregister`` are called by the extension's top-level ``__init__``.
"""
from __future__ import annotations

import bpy

from . import animation_ui, jobs, operators, panels, plan_ui, preferences, properties, rig_retarget, shape_sync

classes = (*properties.classes, *preferences.classes, *jobs.classes, *operators.classes, *plan_ui.classes,
           *panels.classes, *rig_retarget.classes, *animation_ui.classes)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    properties.register()
    shape_sync.register()
    jobs.register()
    rig_retarget.register()
    animation_ui.register()


def unregister():
    animation_ui.unregister()
    rig_retarget.unregister()
    jobs.unregister()
    shape_sync.unregister()
    properties.unregister()
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
