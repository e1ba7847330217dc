"""Add-on preferences (Edit > Preferences > Add-ons > ShapeMove): body model, the Python that runs
the heavy jobs, where models live, which model is active, and the device."""
from __future__ import annotations

import bpy
from bpy.props import EnumProperty, StringProperty

# the extension's top-level package, e.g. "bl_ext.user_default.shapemove"
ADDON_ID = __package__.rpartition(".")[0] or __package__


class ShapeMovePreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_ID

    body_model: EnumProperty(
        name="Body model", default="OPENBODY",
        items=[("OPENBODY", "OpenBody", "The body model shipped with ShapeMove"),
               ("SMPL", "SMPL family", "Your own SMPL / SMPL-H / SMPL-X model file (not shipped: licence)")],
    )
    smpl_path: StringProperty(
        name="SMPL model file", subtype="FILE_PATH", default="",
        description="SMPL/SMPL-H/SMPL-X .npz or .pkl you downloaded (or the folder holding it)",
    )
    python_env: StringProperty(
        name="Python environment", subtype="FILE_PATH", default="",
        description="Python executable (or its virtual environment folder) with torch, used for generation, "
                    "retargeting, search and training. Empty: Blender's Python if torch imports there",
    )
    models_dir: StringProperty(
        name="Models folder", subtype="DIR_PATH", default="",
        description="Folder with trained ShapeMove checkpoints (empty: the default location)",
    )
    active_model: StringProperty(
        name="Active model", subtype="DIR_PATH", default="",
        description="Model folder (savae.pt, t5/, tma/) used for generation and search (empty: the default model)",
    )
    device: EnumProperty(
        name="Device", default="cpu",
        items=[("cpu", "CPU", "Run the networks on the processor"), ("cuda", "CUDA", "Run them on an NVIDIA GPU")],
    )

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "body_model")
        if self.body_model == "SMPL":
            layout.prop(self, "smpl_path")
        row = layout.row(align=True)
        row.prop(self, "python_env")
        row.operator("shapemove.detect_python", text="", icon="VIEWZOOM")
        layout.prop(self, "models_dir")
        layout.prop(self, "active_model")
        layout.prop(self, "device", expand=True)


def preferences(context=None):
    """The preferences, or None when running outside an installed extension (command line)."""
    context = context or bpy.context
    addon = context.preferences.addons.get(ADDON_ID)
    return addon.preferences if addon else None


def body_spec(context=None) -> str:
    """What the worker's ops take as "body": "openbody" or the SMPL-family file path."""
    prefs = preferences(context)
    if prefs is not None and prefs.body_model == "SMPL" and prefs.smpl_path:
        return bpy.path.abspath(prefs.smpl_path)
    return "openbody"


def setting(name: str, default="", context=None):
    """One preference value (``default`` outside an installed extension)."""
    prefs = preferences(context)
    value = getattr(prefs, name, default) if prefs is not None else default
    if isinstance(value, str) and value and name in ("models_dir", "active_model", "smpl_path"):
        value = bpy.path.abspath(value)
    return value


classes = (ShapeMovePreferences,)
