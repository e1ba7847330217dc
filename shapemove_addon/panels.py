"""Sidebar panels (View3D > Sidebar > ShapeMove): Generate, Shape, Retarget, Library, Train, Export.

Panels only draw; every change goes through an operator or a property (see operators.py,
properties.py). A panel whose job runs shows its progress and a Cancel button instead of its start
button.
"""
from __future__ import annotations

import bpy

from ..core.constants import NUM_BETAS
from ..core.generation.model_bundle import known_actions
from . import job_submit, jobs, semantic_shape
from .plan_ui import draw_plan
from .preferences import setting
from .redecode import HAS_TOKENS_KEY
from .rig_state import PHYSICS_KEY, PROVENANCE_KEY, TAKE_NOTES_KEY, rig_of


def _job_fraction(kind: str):
    """(fraction, status text) of the panel's running job, or None."""
    if not job_submit.running(kind):
        return None
    mgr = jobs.manager()
    job = mgr.jobs.get(job_submit.RUNNING[kind])
    return (job.fraction if job is not None else 0.0), mgr.status


def draw_job(layout, kind: str, operator: str, text: str, icon: str = "PLAY", **props):
    """The start button, or progress + Cancel while the panel's job runs."""
    state = _job_fraction(kind)
    if state is None:
        op = layout.operator(operator, text=text, icon=icon)
        for k, v in props.items():
            setattr(op, k, v)
        return
    fraction, status = state
    row = layout.row(align=True)
    if hasattr(row, "progress"):  # Blender 4.0+
        row.progress(factor=fraction, type="BAR", text=status or f"{100 * fraction:.0f}%")
    else:
        row.label(text=status or f"{100 * fraction:.0f}%")
    row.operator("shapemove.cancel_job", text="", icon="CANCEL").kind = kind


def draw_optional(layout, data, toggle: str, value: str) -> None:
    """The property ``value`` beside its checkbox ``toggle``, greyed out while the box is off."""
    row = layout.row(align=True)
    row.prop(data, toggle, text="")
    sub = row.row(align=True)
    sub.enabled = getattr(data, toggle)
    sub.prop(data, value)


class _Panel:
    """The add-on's panels: in the 3D view's ShapeMove tab, each one's ``bl_idname`` its class name."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "ShapeMove"

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "bl_idname" not in cls.__dict__:
            cls.bl_idname = cls.__name__


class _SubPanel(_Panel):
    bl_parent_id = "SHAPEMOVE_PT_main"


class _SettingsPanel(_SubPanel):
    """A sub-panel, closed at first, of scene settings in one column: subclasses write
    ``draw_settings(context, settings, col)``; ``settings`` is the scene's ``SETTINGS`` group."""

    bl_options = {"DEFAULT_CLOSED"}
    SETTINGS = "shapemove"

    def draw(self, context):
        self.draw_settings(context, getattr(context.scene, self.SETTINGS), self.layout.column())


class _RigPanel(_SubPanel):
    """A sub-panel shown only while a ShapeMove rig (or one of its meshes) is active."""

    @classmethod
    def poll(cls, context):
        return rig_of(context.active_object) is not None


class SHAPEMOVE_PT_main(_Panel, bpy.types.Panel):
    bl_label = "ShapeMove"

    def draw(self, context):
        layout = self.layout
        layout.operator("shapemove.build_from_motion", icon="ARMATURE_DATA")
        wm = context.window_manager
        status = getattr(wm, "shapemove_status", "")
        if status:
            row = layout.row(align=True)
            row.label(text=status, icon="INFO")
            if hasattr(bpy.types, "SHAPEMOVE_OT_cancel_jobs"):
                row.operator("shapemove.cancel_jobs", text="", icon="CANCEL")


class SHAPEMOVE_PT_generate(_SubPanel, bpy.types.Panel):
    bl_label = "Generate"

    def draw(self, context):
        s = context.scene.shapemove
        col = self.layout.column()
        col.prop(s, "prompt", text="")
        draw_plan(col, s)   # the plan's fields under the prompt (plan_ui.py)
        known = known_actions(setting("active_model") or None, 10)  # what the model was trained on
        if known:
            col.label(text="Knows: " + ", ".join(known), icon="INFO")
        col.prop(s, "shape_text")
        draw_optional(col, s, "use_seconds", "seconds")
        row = col.row(align=True)
        row.prop(s, "seed")
        row.prop(s, "temperature")
        col.prop(s, "by_parts")
        col.prop(s, "use_captured")
        if s.library_folder:
            col.prop(s, "use_library")
        draw_job(col, "generate", "shapemove.generate", "Generate")
        rig = rig_of(context.active_object)
        if rig is not None:
            draw_result(col, rig)


# (custom property key, label, format) of the physics figures a generation leaves on its rig
PHYSICS_FIGURES = (("penetrate_cm", "Penetrate", "{:.2f} cm"), ("float_cm", "Float", "{:.2f} cm"),
                   ("skate_pct", "Skate", "{:.1f} %"), ("dyn_stable_pct", "Stability", "{:.0f} %"))
MEASUREMENTS = (("height_cm", "Height"), ("chest_cm", "Chest"), ("waist_cm", "Waist"), ("hip_cm", "Hips"))
BODY_MASS = (("mass_kg", "Mass", "{:.1f} kg"), ("bmi", "BMI", "{:.1f}"))  # mesh volume x 985 kg/m^3; kg/m^2


def draw_result(layout, rig) -> None:
    """The active rig's motion physics (from its generation) and body measurements, if known."""
    physics = rig.get(PHYSICS_KEY) or {}
    m = rig.shapemove
    nearest = list(rig.get("shapemove_nearest_actions") or [])  # the prompt was far from the training data
    lacking = list(rig.get("shapemove_model_warnings") or [])   # a part the model folder lacks (no TMA)
    parts = list(rig.get("shapemove_parts") or [])               # generated by body part (core/generation/parts.py)
    notes = list(rig.get(TAKE_NOTES_KEY) or [])                  # a take the model's codes miss, played as captured
    source = str(rig.get(PROVENANCE_KEY) or "")                  # "captured: HDM05 bd kickLFront 003 (...)", "generated"
    if not physics and m.height_cm <= 0 and not nearest and not lacking and not parts and not notes and not source:
        return
    box = layout.box()
    box.label(text=rig.name, icon="ARMATURE_DATA")
    if nearest:
        box.label(text="Prompt unlike the training data; closest: " + ", ".join(nearest), icon="ERROR")
    for w in lacking:
        box.label(text=w, icon="ERROR")
    for line in parts:
        box.label(text=line, icon="MOD_ARMATURE")
    for part in source.split("; ") if source else []:   # a timeline: "segment 1: generated; segment 2: captured: ..."
        box.label(text=part[:1].upper() + part[1:], icon="REC" if "captured:" in part else "INFO")
    for line in notes:
        box.label(text=line, icon="INFO")
    if physics:
        grid = box.grid_flow(columns=2, align=True)
        for key, label, fmt in PHYSICS_FIGURES:
            if key in physics:
                grid.label(text=f"{label}: {fmt.format(physics[key])}")
    if m.height_cm > 0:
        grid = box.grid_flow(columns=2, align=True)
        for prop, label in MEASUREMENTS:
            grid.label(text=f"{label}: {getattr(m, prop):.1f} cm")
        for prop, label, fmt in BODY_MASS:
            if getattr(m, prop) > 0:
                grid.label(text=f"{label}: {fmt.format(getattr(m, prop))}")


class SHAPEMOVE_PT_shape(_RigPanel, bpy.types.Panel):
    bl_label = "Shape"

    def draw(self, context):
        rig = rig_of(context.active_object)
        s = context.scene.shapemove
        layout = self.layout
        if semantic_shape.semantic_body(rig) is not None:
            col = layout.column(align=True)
            for name in semantic_shape.PHENOTYPES:
                col.prop(rig.shapemove, name, slider=True)
        row = layout.row(align=True)
        row.operator("shapemove.random_shape", text="Random", icon="MOD_NOISE")
        row.operator("shapemove.reset_shape", text="Reset", icon="LOOP_BACK")
        row.prop(s, "random_scale", text="")
        col = layout.column(align=True)
        col.prop(s, "shape_from_text", text="")
        draw_job(col, "shape", "shapemove.shape_from_text", "Apply Shape from Text", icon="FONT_DATA")
        if rig.get(HAS_TOKENS_KEY):
            row = layout.row(align=True)
            row.prop(s, "auto_redecode")
            row.operator("shapemove.redecode", text="", icon="FILE_REFRESH")
        box = layout.box()
        m = rig.shapemove
        if m.height_cm > 0:
            grid = box.grid_flow(columns=2, align=True)
            for prop in ("height_cm", "chest_cm", "waist_cm", "hip_cm", "mass_kg", "bmi"):
                if prop in ("height_cm", "chest_cm", "waist_cm", "hip_cm") or getattr(m, prop) > 0:
                    grid.label(text=f"{m.bl_rna.properties[prop].name}: {getattr(m, prop):.1f}")
        draw_job(box, "measure", "shapemove.measure", "Measure", icon="DRIVER_DISTANCE")


class SHAPEMOVE_PT_shape_betas(_RigPanel, bpy.types.Panel):
    bl_label = "Betas"
    bl_parent_id = "SHAPEMOVE_PT_shape"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        rig = rig_of(context.active_object)
        col = self.layout.column(align=True)
        for i in range(NUM_BETAS):
            col.prop(rig.shapemove, "betas", index=i, text=f"Beta {i}", slider=True)


class SHAPEMOVE_PT_retarget(_SettingsPanel, bpy.types.Panel):
    bl_label = "Retarget"

    def draw_settings(self, context, s, col):
        col.row().prop(s, "retarget_source", expand=True)
        if s.retarget_source == "FILE":
            col.prop(s, "retarget_path", text="")
            row = col.row(align=True)
            row.prop(s, "retarget_source_fps")
            row.prop(s, "retarget_angle_unit", text="")
        else:
            obj = context.active_object
            col.label(text=f"Source: {obj.name}" if obj is not None and obj.type == "ARMATURE" else
                      "Make the source armature active", icon="ARMATURE_DATA")
        col.prop(s, "retarget_target")
        draw_job(col, "retarget", "shapemove.retarget", "Retarget", icon="CON_ARMATURE")


class SHAPEMOVE_UL_library(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index=0, flt_flag=0):
        row = layout.row(align=True)
        row.label(text=item.caption or item.name, icon="ANIM")
        row.label(text=f"{item.score:.2f}")


class SHAPEMOVE_PT_library(_SettingsPanel, bpy.types.Panel):
    bl_label = "Library"

    def draw_settings(self, context, s, col):
        col.prop(s, "library_folder", text="")
        row = col.row(align=True)
        row.prop(s, "library_query", text="", icon="VIEWZOOM")
        row.prop(s, "library_top_k", text="")
        draw_job(col, "search", "shapemove.library_search", "Search", icon="VIEWZOOM")
        if len(s.library_results):
            col.template_list("SHAPEMOVE_UL_library", "", s, "library_results", s, "library_index", rows=4)
            col.operator("shapemove.library_import", icon="IMPORT").index = -1


class SHAPEMOVE_PT_train(_SettingsPanel, bpy.types.Panel):
    bl_label = "Train"

    def draw_settings(self, context, s, col):
        col.prop(s, "train_data")
        col.row().prop(s, "train_kind", expand=True)
        col.prop(s, "train_model_name")
        row = col.row(align=True)
        row.prop(s, "train_steps")
        row.prop(s, "train_config", text="")
        if job_submit.running("train"):
            draw_job(col, "train", "shapemove.train", "Start")
        else:
            row = col.row(align=True)
            row.operator("shapemove.train", text="Start", icon="PLAY").resume = False
            row.operator("shapemove.train", text="Resume", icon="FF").resume = True
        if s.train_result:
            box = col.box()
            box.label(text=s.train_result, icon="CHECKMARK")
            box.operator("shapemove.use_model", icon="MODIFIER").directory = s.train_result
        col.label(text=f"Active model: {setting('active_model') or 'default'}")


class SHAPEMOVE_PT_export(_RigPanel, bpy.types.Panel):
    bl_label = "Export"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        s = context.scene.shapemove
        row = self.layout.row(align=True)
        row.prop(s, "export_format", text="")
        row.operator("shapemove.export", text="Export", icon="EXPORT").format = s.export_format


classes = (SHAPEMOVE_PT_main, SHAPEMOVE_PT_generate, SHAPEMOVE_PT_shape, SHAPEMOVE_PT_shape_betas,
           SHAPEMOVE_PT_retarget, SHAPEMOVE_UL_library, SHAPEMOVE_PT_library, SHAPEMOVE_PT_train,
           SHAPEMOVE_PT_export)
