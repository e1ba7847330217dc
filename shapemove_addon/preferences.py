"""Add-on preferences (Edit > Preferences > Add-ons > ShapeMove)."""
from __future__ import annotations

import bpy
from bpy.props import StringProperty

# the extension's top-level package, e.g. "bl_ext.user_default.shapemove"
ADDON_ID = __package__.rpartition(".")[0] or __package__


class ShapeMovePreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_ID

    models_dir: StringProperty(
        name="Models folder", subtype="DIR_PATH", default="",
        description="Folder with trained ShapeMove checkpoints (empty: the default location)",
    )

    def draw(self, context):
        self.layout.prop(self, "models_dir")


def preferences(context=None):
    """The preferences, or None when running outside an installed extension (command line)."""
    context = context or bpy.context
    addon = context.preferences.addons.get(ADDON_ID)
    return addon.preferences if addon else None


classes = (ShapeMovePreferences,)
