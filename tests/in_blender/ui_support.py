"""What the in-Blender UI tests share: the config, the extension's modules, a layout that checks
panel code against Blender's RNA, and small scene helpers. Importing it sets up the process:
BLENDER_USER_RESOURCES and SHAPEMOVE_HOME from the config ($SHAPEMOVE_BLENDER_CONFIG), no
SHAPEMOVE_PYTHON, and torch made unimportable (Blender's Python usually lacks it) until a test
calls ``allow_torch()``.

Panels are drawn with ``RnaLayout``: Blender as a module has no window to draw into (a real popup
crashes it), so each panel's real ``draw`` gets a layout object that checks every call against
Blender's RNA (the property exists on the data, the operator and its properties exist, icons are
valid names, UIList types are registered) and records what was drawn.
"""
from __future__ import annotations

import importlib
import json
import os
import sys
import time
from types import FunctionType, SimpleNamespace

import numpy as np

CONFIG = json.loads(open(os.environ["SHAPEMOVE_BLENDER_CONFIG"]).read())
os.environ["BLENDER_USER_RESOURCES"] = CONFIG["user_resources"]
os.environ["SHAPEMOVE_HOME"] = CONFIG["home"]
os.environ.pop("SHAPEMOVE_PYTHON", None)
sys.modules["torch"] = None  # `import torch` raises ImportError, as in a stock Blender

import bpy  # noqa: E402

ADDON = "bl_ext.user_default.shapemove"
MM = 1e-3


def ext(name):
    """A module of the installed extension (bl_ext.user_default.shapemove.<name>)."""
    return importlib.import_module(f"{ADDON}.{name}")


def torch_imported() -> bool:
    return isinstance(sys.modules.get("torch"), type(sys))


def allow_torch():
    """From here on torch imports (the jobs run in this process)."""
    if sys.modules.get("torch", 0) is None:
        del sys.modules["torch"]
    import torch

    return torch


def install():
    """The factory startup scene (cube, camera, light) with the extension zip installed."""
    bpy.ops.wm.read_factory_settings(use_empty=False)
    return bpy.ops.extensions.package_install_files(filepath=CONFIG["zip"], repo="user_default", enable_on_install=True)


# -- a layout that checks panel code against Blender's RNA ---------------------------------------
ICONS = set(bpy.types.UILayout.bl_rna.functions["label"].parameters["icon"].enum_items.keys())
LAYOUT_ATTRS = {"enabled", "active", "alert", "scale_x", "scale_y", "use_property_split",
                "use_property_decorate", "operator_context", "alignment"}


class OperatorProps:
    """What ``layout.operator`` returns: only the operator's real properties can be set."""

    def __init__(self, idname, record):
        mod, name = idname.split(".")
        self._rna = getattr(getattr(bpy.ops, mod), name).get_rna_type()  # raises for unknown operators
        self._record = record

    def __setattr__(self, key, value):
        if key.startswith("_"):
            return object.__setattr__(self, key, value)
        prop = self._rna.properties.get(key)
        if prop is None:
            raise AttributeError(f"operator {self._rna.identifier} has no property {key!r}")
        if prop.type == "ENUM" and value not in prop.enum_items.keys():
            raise ValueError(f"{self._rna.identifier}.{key}: {value!r} is not one of {prop.enum_items.keys()}")
        self._record["props"][key] = value


class RnaLayout:
    def __init__(self, log):
        object.__setattr__(self, "log", log)

    def __setattr__(self, key, value):
        if key not in LAYOUT_ATTRS:
            raise AttributeError(f"UILayout has no attribute {key!r}")
        object.__setattr__(self, key, value)

    @staticmethod
    def _icon(icon):
        if icon not in ICONS:
            raise ValueError(f"unknown icon {icon!r}")

    def _child(self, *args, **kwargs):
        return RnaLayout(self.log)

    row = column = box = split = grid_flow = column_flow = _child

    def prop(self, data, prop, text=None, icon="NONE", index=-1, expand=False, slider=False, **kw):
        self._icon(icon)
        p = data.bl_rna.properties.get(prop)
        if p is None:
            raise AttributeError(f"{data.bl_rna.identifier} has no property {prop!r}")
        value = getattr(data, prop)  # runs getters, as drawing does
        if index >= 0:
            value = value[index]
        self.log.append({"kind": "prop", "data": data.bl_rna.identifier, "prop": prop, "index": index,
                         "text": text, "value": value if isinstance(value, (int, float, str, bool)) else None})

    def operator(self, idname, text=None, icon="NONE", **kw):
        self._icon(icon)
        rec = {"kind": "operator", "op": idname, "text": text, "props": {}}
        props = OperatorProps(idname, rec)
        self.log.append(rec)
        return props

    def label(self, text="", icon="NONE", **kw):
        self._icon(icon)
        self.log.append({"kind": "label", "text": text})

    def progress(self, factor=0.0, type="BAR", text=""):
        assert 0.0 <= factor <= 1.0, factor
        self.log.append({"kind": "progress", "factor": factor, "text": text})

    def template_list(self, listtype_name, list_id, dataptr, propname, active_dataptr, active_propname, **kw):
        if not hasattr(bpy.types, listtype_name):
            raise AttributeError(f"UIList {listtype_name!r} is not registered")
        for data, prop in ((dataptr, propname), (active_dataptr, active_propname)):
            if data.bl_rna.properties.get(prop) is None:
                raise AttributeError(f"{data.bl_rna.identifier} has no property {prop!r}")
        ui_list = getattr(bpy.types, listtype_name)
        for i, item in enumerate(getattr(dataptr, propname)):  # draw each row like Blender would
            ui_list.draw_item(SimpleNamespace(), bpy.context, RnaLayout(self.log), dataptr, item, 0, active_dataptr,
                              active_propname, i)
        self.log.append({"kind": "list", "type": listtype_name, "rows": len(getattr(dataptr, propname))})

    def separator(self, **kw):
        pass


class PanelSelf:
    """Stands in for the panel instance Blender passes to ``draw``: the layout, and the panel class's
    attributes and methods (a panel's draw may call its own helpers)."""

    def __init__(self, cls, layout):
        self.cls, self.layout = cls, layout

    def __getattr__(self, name):
        value = getattr(self.cls, name)
        return value.__get__(self) if isinstance(value, FunctionType) else value


def addon_panels():
    mod = ext("shapemove_addon.panels")
    return [c for c in mod.classes if issubclass(c, bpy.types.Panel)]


def draw_panels(context=None) -> dict:
    """{panel id: None (poll false) | list of drawn items}; a panel whose draw raises -> exception text."""
    context = context or bpy.context
    out = {}
    for cls in addon_panels():
        if hasattr(cls, "poll") and not cls.poll(context):
            out[cls.bl_idname] = None
            continue
        log: list = []
        cls.draw(PanelSelf(cls, RnaLayout(log)), context)
        out[cls.bl_idname] = log
    return out


def draw_preferences():
    prefs = bpy.context.preferences.addons[ADDON].preferences
    log: list = []

    class Self:
        layout = RnaLayout(log)

        def __getattr__(self, name):
            return getattr(prefs, name)

    type(prefs).draw(Self(), bpy.context)
    return log


# -- helpers ---------------------------------------------------------------------------------------
def counts():
    return {k: len(getattr(bpy.data, k)) for k in ("objects", "meshes", "armatures", "actions", "collections")}


def bone_heads(arm, names):
    return np.array([list(arm.data.bones[n].head_local) for n in names])


def skeleton_height(arm):
    b = arm.data.bones
    return b["head"].head_local.z - min(b["left_ankle"].head_local.z, b["right_ankle"].head_local.z)


def posed_heads(arm, names):
    return np.array([list(arm.matrix_world @ arm.pose.bones[n].head) for n in names])


def keyed_frames(obj) -> int:
    kf = ext("shapemove_addon.keyframes")
    action = obj.animation_data.action
    frames = {round(k.co[0], 3) for fc in kf.action_fcurves(action, obj) for k in fc.keyframe_points}
    return len(frames)


def report_error(fn):
    """Run an operator call; -> ("ok", result) or ("error", message)."""
    try:
        return ["ok", sorted(fn())]
    except RuntimeError as exc:
        return ["error", str(exc)]


def run_jobs(timeout=120.0):
    """What Blender's timer does: poll the job manager until no job is left."""
    mgr = ext("shapemove_addon.jobs").manager()
    end = time.monotonic() + timeout
    while mgr.busy and time.monotonic() < end:
        mgr.poll()
        time.sleep(0.02)
    return not mgr.busy


def job_messages():
    """Record the error messages of the jobs that end in an error (instead of popups)."""
    errors: list = []
    jobs = ext("shapemove_addon.jobs")
    original = jobs.report_error
    jobs.report_error = lambda text: errors.append(text)
    return errors, lambda: setattr(jobs, "report_error", original)
