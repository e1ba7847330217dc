"""Operators of the ShapeMove panels.

Quick ones (build, shape, export) change the scene directly, undoably. Heavy ones (generate,
retarget, search, train, measure, shape from text) start a job (``job_submit``) and return at once;
the job's callback changes the scene when it answers (a rig is built through the build operator,
so it is one undo step). Every ShapeMoveError becomes an ERROR report and leaves the scene as it was.
"""
from __future__ import annotations

import os
from pathlib import Path

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from ..core.constants import NUM_BETAS, is_openbody
from ..core.errors import ShapeMoveError
from ..core.scene.bodies import load_body
from ..core.scene.motion_file import load_motion
from . import job_submit, paths, redecode, semantic_shape, shape_sync
from .export import FORMATS, export_rig
from .jobs import report_error
from .preferences import body_spec, preferences, setting
from .redecode import HAS_TOKENS_KEY, MOTION_FILE_KEY
from .rig_state import PHYSICS_KEY, PROVENANCE_KEY, TAKE_NOTES_KEY, current_betas, rig_body_spec, rig_of
from .animation_rig import ROOT_MOTION_ITEMS, build_animated_rig
from .scene_build import SLIDER_RANGE

MEASUREMENT_PROPS = ("height_cm", "chest_cm", "waist_cm", "hip_cm", "mass_kg", "bmi")


def active_rig(context):
    return rig_of(context.active_object)


def store_measurements(rig, measurements: dict) -> None:
    for prop in MEASUREMENT_PROPS:
        value = measurements.get(prop)
        if isinstance(value, (int, float)):
            setattr(rig.shapemove, prop, float(value))


def store_physics(rig, physics: dict) -> None:
    """Keep the job's physics figures (penetrate_cm, float_cm, skate_pct, dyn_stable_pct) on the rig."""
    rig[PHYSICS_KEY] = {k: float(v) for k, v in physics.items() if isinstance(v, (int, float))}


def build_rig_from_file(path: str, name: str = "ShapeMove", measurements: dict | None = None,
                        physics: dict | None = None):
    """From a job callback: build the rig through the (undoable) build operator; errors -> popup."""
    try:
        bpy.ops.shapemove.build_from_motion(filepath=str(path), rig_name=name)
    except RuntimeError as exc:  # the operator's ERROR report
        report_error(str(exc).replace("Error: ", "").strip())
        return None
    rig = active_rig(bpy.context)
    if rig is not None and measurements:
        store_measurements(rig, measurements)
    if rig is not None and physics:
        store_physics(rig, physics)
    return rig


def existing_path(value: str, what: str, folder: bool = False) -> str:
    """A file or folder setting of the panels as an absolute path that exists; else a ShapeMoveError
    'WHAT not found: PATH'."""
    path = bpy.path.abspath(value) if value else ""
    if not path or not (os.path.isdir(path) if folder else os.path.isfile(path)):
        raise ShapeMoveError(f"{what} not found: {path or '(none given)'}")
    return path


def set_whole_shape(rig, betas, context) -> None:
    """Set all of the rig's betas at once (random, reset, from text); the phenotype sliders are
    re-derived from them."""
    semantic_shape.forget_phenotype(rig)
    shape_sync.set_betas(rig, betas, context)


def on_generated(name: str, msg: dict, prompt: str | None = None):
    """The generate job's answer: build the rig, with its measurements and physics figures; the plan
    it was made from shown under the prompt (``prompt``: the one generated; ``plan_ui.py``)."""
    if msg.get("cancelled"):
        return None
    r = msg["result"]
    rig = build_rig_from_file(r["path"], name, r.get("measurements"), r.get("physics"))
    model = [str(w) for w in r.get("model_warnings") or []]  # what the model folder lacks (e.g. no TMA)
    if rig is not None and [w for w in r.get("warnings") or [] if w not in model]:
        # far from the training data: the panel names the closest actions
        rig["shapemove_nearest_actions"] = [str(a) for a in r.get("nearest_actions") or []][:3] or ["?"]
    if rig is not None and model:
        rig["shapemove_model_warnings"] = model
    if rig is not None and r.get("parts"):
        rig["shapemove_parts"] = [str(p) for p in r["parts"]][:2]  # two things at once, a side mirrored
    keep_notes(rig, r)   # a library clip played as captured
    if rig is not None and r.get("provenance"):
        rig[PROVENANCE_KEY] = str(r["provenance"])   # "captured: HDM05 bd kickLFront 003 (CC BY-SA 3.0)" or "generated"
    if r.get("plan"):   # the plan it was made from, under the prompt to change and generate again
        import json

        from .plan_fields import show_plan

        plan = json.loads(r["plan"])
        s = bpy.context.scene.shapemove
        show_plan(s, plan, prompt or s.prompt)
    return rig


def keep_notes(rig, result: dict) -> None:
    """A job's notes (a take played by its own rotations, and why) kept on the rig it built, for the
    panel (at most two lines)."""
    notes = [str(n) for n in result.get("notes") or []]
    if rig is not None and notes:
        rig[TAKE_NOTES_KEY] = notes[:2]


class ReportingOperator:
    """execute -> self.start(context) (returns a message or None); ShapeMoveError -> ERROR report.
    The one execute of the add-on's operators that only report (rig_retarget's too)."""

    def execute(self, context):
        try:
            message = self.start(context)
        except ShapeMoveError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        if message:
            self.report({"INFO"}, message)
        return {"FINISHED"}


class JobOperator(ReportingOperator):
    """A ReportingOperator whose start submits the background job ``job`` (the kind that
    ``job_submit`` and the panel's ``draw_job`` know it by): greyed out while that job runs."""

    job = ""

    @classmethod
    def poll(cls, context):
        return not job_submit.running(cls.job)


# -- build ---------------------------------------------------------------------------------------
class SHAPEMOVE_OT_build_from_motion(ReportingOperator, bpy.types.Operator, ImportHelper):
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
    root_motion: EnumProperty(name="Root Motion", items=ROOT_MOTION_ITEMS, default="PELVIS",
                              description="Where the horizontal travel goes (docs/animation.md)")

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def start(self, context):
        motion = load_motion(self.filepath)
        model_file = self.body_model_file or (body_spec(context) if not is_openbody(motion.body_model) else None)
        if model_file == "openbody":
            model_file = None
        rig = build_animated_rig(context, motion, load_body(motion.body_model, model_file), name=self.rig_name,
                                 collection=context.collection, root_motion=self.root_motion)
        rig.armature[MOTION_FILE_KEY] = os.path.abspath(self.filepath)
        rig.armature[HAS_TOKENS_KEY] = motion.remakeable   # tokens to decode again, or a take to plant again
        for obj in context.view_layer.objects:
            obj.select_set(False)
        rig.armature.select_set(True)
        context.view_layer.objects.active = rig.armature
        return f"built {rig.armature.name}: {motion.num_frames} frames at {motion.fps:g} fps"


# -- generate ------------------------------------------------------------------------------------
def scene_prompt(context) -> str:
    """The Generate panel's prompt, stripped; an empty one is a ShapeMoveError."""
    prompt = context.scene.shapemove.prompt.strip()
    if not prompt:
        raise ShapeMoveError("the prompt is empty: describe a motion, e.g. 'a person jogs forward and waves'")
    return prompt


def generation_params(context, label: str) -> dict:
    """The job parameters every generation shares: the Generate panel's shape text, seed and temperature,
    the active model and body, and a new motion file named after ``label``."""
    s = context.scene.shapemove
    return {"shape_text": s.shape_text.strip() or None, "seed": s.seed, "temperature": s.temperature,
            "by_parts": bool(s.by_parts), "model": setting("active_model") or None, "body": body_spec(context),
            "out": str(paths.new_motion_path(label))}


def library_param(context) -> dict:
    """{"library": folder} when the Generate panel's "Use Library motions" is on and a Library folder
    is set (the user's own motions join the candidates; the folder must exist), else {}."""
    s = context.scene.shapemove
    if s.use_library and s.library_folder:
        return {"library": existing_path(s.library_folder, "library folder", folder=True)}
    return {}


class SHAPEMOVE_OT_generate(JobOperator, bpy.types.Operator):
    """Generate a body shape and a motion from the prompt (runs in the background)"""

    bl_idname = "shapemove.generate"
    bl_label = "Generate"
    job = "generate"

    def start(self, context):
        s = context.scene.shapemove
        prompt = scene_prompt(context)
        from .plan_fields import plan_param

        params = {**generation_params(context, prompt), "prompt": prompt,
                  "seconds": s.seconds if s.use_seconds else None, "captured": bool(s.use_captured),
                  **library_param(context), **plan_param(s)}
        name = paths.slug(prompt, 24)

        job_submit.submit_job("generate", params, kind=self.job, label="generate",
                              on_result=lambda msg: on_generated(name, msg, prompt))
        return "generating..."


class SHAPEMOVE_OT_cancel_job(bpy.types.Operator):
    """Cancel this panel's running job (training stops after saving a checkpoint)"""

    bl_idname = "shapemove.cancel_job"
    bl_label = "Cancel"

    kind: StringProperty(name="Job", default="generate")

    def execute(self, context):
        if not job_submit.cancel(self.kind):
            self.report({"WARNING"}, f"no {self.kind} job is running")
            return {"CANCELLED"}
        return {"FINISHED"}


# -- shape ---------------------------------------------------------------------------------------
class _RigOperator:
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.mode in ("OBJECT", "POSE") and active_rig(context) is not None


class SHAPEMOVE_OT_random_shape(ReportingOperator, _RigOperator, bpy.types.Operator):
    """Give the active rig a random body shape (betas ~ N(0, spread))"""

    bl_idname = "shapemove.random_shape"
    bl_label = "Random Shape"

    seed: IntProperty(name="Seed", default=-1, min=-1, description="-1: a new random shape every time")

    def start(self, context):
        rng = np.random.default_rng(None if self.seed < 0 else self.seed)
        betas = np.clip(rng.normal(0.0, context.scene.shapemove.random_scale, NUM_BETAS),
                        -SLIDER_RANGE, SLIDER_RANGE)
        set_whole_shape(active_rig(context), betas, context)


class SHAPEMOVE_OT_reset_shape(ReportingOperator, _RigOperator, bpy.types.Operator):
    """Reset the active rig to the average body (all betas 0)"""

    bl_idname = "shapemove.reset_shape"
    bl_label = "Reset Shape"

    def start(self, context):
        set_whole_shape(active_rig(context), np.zeros(NUM_BETAS), context)


class SHAPEMOVE_OT_shape_from_text(ReportingOperator, _RigOperator, bpy.types.Operator):
    """Set the active rig's shape from a sentence with measurements (height, chest, waist, ...)"""

    bl_idname = "shapemove.shape_from_text"
    bl_label = "Apply Shape from Text"
    bl_options = {"REGISTER"}

    def start(self, context):
        rig = active_rig(context)
        text = context.scene.shapemove.shape_from_text.strip()
        if not text:
            raise ShapeMoveError("write a shape sentence first, e.g. 'a man with a height of 185 cm'")
        name = rig.name

        def done(msg):
            target = bpy.data.objects.get(name)
            if target is None or msg.get("cancelled"):
                return
            set_whole_shape(target, msg["result"]["betas"], bpy.context)
            store_measurements(target, msg["result"].get("achieved", {}))

        job_submit.submit_job("betas_from_text", {"text": text, "body": rig_body_spec(rig)}, kind="shape",
                              label="shape from text", on_result=done)
        return "fitting the shape..."


class SHAPEMOVE_OT_measure(ReportingOperator, _RigOperator, bpy.types.Operator):
    """Measure the active rig's body (height, chest, waist, hip in cm)"""

    bl_idname = "shapemove.measure"
    bl_label = "Measure"
    bl_options = {"REGISTER"}

    def start(self, context):
        rig = active_rig(context)
        name = rig.name

        def done(msg):
            target = bpy.data.objects.get(name)
            if target is not None and not msg.get("cancelled"):
                store_measurements(target, msg["result"])

        params = {"betas": current_betas(rig).tolist(), "body": rig_body_spec(rig)}
        job_submit.submit_job("measure", params, kind="measure", label="measure", on_result=done)
        return ""


class SHAPEMOVE_OT_redecode(ReportingOperator, _RigOperator, bpy.types.Operator):
    """Decode the rig's motion tokens again for its current body"""

    bl_idname = "shapemove.redecode"
    bl_label = "Re-decode Motion for This Body"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        rig = active_rig(context)
        return rig is not None and bool(rig.get(HAS_TOKENS_KEY))

    def start(self, context):
        redecode.submit(active_rig(context))
        return "re-decoding..."


# -- retarget ------------------------------------------------------------------------------------
def _retarget_job(context, source: str, target_rig, name: str, read: dict | None = None) -> None:
    params = {"source": source, "body": rig_body_spec(target_rig), "model": setting("active_model") or None,
              "out": str(paths.new_motion_path(name)), **(read or {})}
    if target_rig is not None:
        params["betas"] = current_betas(target_rig).tolist()

    def done(msg):
        if msg.get("cancelled"):
            return
        keep_notes(build_rig_from_file(msg["result"]["path"], name), msg["result"])   # the codec missed the take

    job_submit.submit_job("retarget", params, kind="retarget", label=f"retarget {Path(source).name}", on_result=done)


def reader_overrides(s) -> dict:
    """The panel's overrides of what a mocap file declares (the CLI's --source-fps / --angle-unit)."""
    out = {}
    if s.retarget_source_fps > 0:
        out["source_fps"] = float(s.retarget_source_fps)
    if s.retarget_angle_unit != "FILE":
        out["angle_unit"] = s.retarget_angle_unit.lower()
    return out


class SHAPEMOVE_OT_retarget(JobOperator, bpy.types.Operator):
    """Put a mocap clip (BVH, ASF/AMC, AMASS) or the active armature's action on a ShapeMove body"""

    bl_idname = "shapemove.retarget"
    bl_label = "Retarget"
    job = "retarget"

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and super().poll(context)

    def start(self, context):
        s = context.scene.shapemove
        target = s.retarget_target or active_rig(context)
        read = {}
        if s.retarget_source == "FILE":
            source = existing_path(s.retarget_path, "motion file")
            read = reader_overrides(s)
            name = Path(source).stem
        else:
            arm = context.active_object
            if arm is None or arm.type != "ARMATURE" or rig_of(arm) is arm:
                raise ShapeMoveError("make the armature whose action you want to retarget active (not a ShapeMove rig)")
            if arm.animation_data is None or arm.animation_data.action is None:
                raise ShapeMoveError(f"{arm.name!r} has no action to retarget")
            source = str(paths.new_motion_path(arm.name).with_suffix(".bvh"))
            _export_plain_bvh(context, arm, source)
            name = arm.name
            target = s.retarget_target
        _retarget_job(context, source, target, name, read)
        return f"retargeting {Path(source).name}..."


def _export_plain_bvh(context, arm, path: str) -> None:
    lo, hi = arm.animation_data.action.frame_range
    with context.temp_override(active_object=arm, object=arm, selected_objects=[arm]):
        try:
            bpy.ops.export_anim.bvh(filepath=path, frame_start=int(lo), frame_end=int(hi), root_transform_only=True)
        except RuntimeError as exc:
            raise ShapeMoveError(f"could not write {arm.name!r} as BVH: {exc}") from None


# -- library -------------------------------------------------------------------------------------
class SHAPEMOVE_OT_library_search(JobOperator, bpy.types.Operator):
    """Rank the motions of the library folder by the query (text-motion alignment model)"""

    bl_idname = "shapemove.library_search"
    bl_label = "Search"
    job = "search"

    def start(self, context):
        s = context.scene.shapemove
        folder = existing_path(s.library_folder, "library folder", folder=True)
        if not s.library_query.strip():
            raise ShapeMoveError("the query is empty: describe a motion, e.g. 'a person waves'")
        scene_name = context.scene.name

        def done(msg):
            scene = bpy.data.scenes.get(scene_name)
            if scene is None or msg.get("cancelled"):
                return
            results = scene.shapemove.library_results
            results.clear()
            for r in msg["result"]["results"]:
                item = results.add()
                item.name, item.score, item.path, item.caption = r["id"], r["score"], r["path"], r["caption"]
            scene.shapemove.library_index = 0

        params = {"folder": folder, "query": s.library_query.strip(), "top_k": s.library_top_k,
                  "tma": setting("active_model") or None}
        job_submit.submit_job("search", params, kind=self.job, label="search", on_result=done)
        return "searching..."


class SHAPEMOVE_OT_library_import(ReportingOperator, bpy.types.Operator):
    """Build a rig from this library motion (mocap files are retargeted first)"""

    bl_idname = "shapemove.library_import"
    bl_label = "Import Motion"
    bl_options = {"REGISTER", "UNDO"}

    index: IntProperty(name="Result", default=-1, description="-1: the selected result")

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def start(self, context):
        s = context.scene.shapemove
        i = s.library_index if self.index < 0 else self.index
        if not 0 <= i < len(s.library_results):
            raise ShapeMoveError("no search result selected")
        item = s.library_results[i]
        path = Path(item.path)
        if path.suffix.lower() == ".npz":
            try:
                load_motion(path)  # a ShapeMove motion file: build it directly
            except ShapeMoveError:
                pass
            else:
                try:
                    bpy.ops.shapemove.build_from_motion(filepath=str(path), rig_name=paths.slug(item.name, 24))
                except RuntimeError as exc:  # its ERROR report
                    raise ShapeMoveError(str(exc).replace("Error: ", "").strip()) from None
                return None  # the build operator reported what it built
        _retarget_job(context, str(path), active_rig(context), paths.slug(item.name, 24))
        return f"retargeting {path.name}..."


# -- train ---------------------------------------------------------------------------------------
class SHAPEMOVE_OT_train(JobOperator, bpy.types.Operator):
    """Train a model part on a dataset folder (runs in the background; cancel keeps a checkpoint)"""

    bl_idname = "shapemove.train"
    bl_label = "Train"
    job = "train"

    resume: BoolProperty(name="Resume", default=False, description="Continue the last (cancelled) run")

    def start(self, context):
        s = context.scene.shapemove
        data = existing_path(s.train_data, "dataset folder", folder=True)
        model_dir = paths.models_dir(context) / paths.slug(s.train_model_name)
        params = {"kind": s.train_kind, "data": data, "model_dir": str(model_dir), "steps": s.train_steps,
                  "resume": self.resume, "device": setting("device", "cpu"), "config": s.train_config,
                  "body": body_spec(context)}
        scene_name = context.scene.name

        def done(msg):
            scene = bpy.data.scenes.get(scene_name)
            r = msg["result"]
            if scene is not None and r.get("published"):
                scene.shapemove.train_result = r["model_dir"]

        job_submit.submit_job("train", params, kind=self.job, label=f"train {s.train_kind}", on_result=done)
        return f"training {s.train_kind} into {model_dir}"


class SHAPEMOVE_OT_use_model(bpy.types.Operator):
    """Use this model folder for generation and search"""

    bl_idname = "shapemove.use_model"
    bl_label = "Use as Active Model"

    directory: StringProperty(name="Model folder", subtype="DIR_PATH", default="")

    def execute(self, context):
        folder = bpy.path.abspath(self.directory or context.scene.shapemove.train_result)
        parts = ("savae.pt", "t5", os.path.join("tma", "tma.pt"))
        if not folder or not any(os.path.exists(os.path.join(folder, p)) for p in parts):
            self.report({"ERROR"}, f"{folder or '(no folder)'} is not a model folder (no savae.pt, t5/ or tma/)")
            return {"CANCELLED"}
        prefs = preferences(context)
        if prefs is None:
            self.report({"ERROR"}, "the ShapeMove preferences are not available (extension not enabled)")
            return {"CANCELLED"}
        prefs.active_model = folder
        return {"FINISHED"}


# -- export --------------------------------------------------------------------------------------
class SHAPEMOVE_OT_export(ReportingOperator, bpy.types.Operator, ExportHelper):
    """Export the active ShapeMove rig with its animation (FBX, glTF or BVH)"""

    bl_idname = "shapemove.export"
    bl_label = "Export Rig"

    filename_ext = ".fbx"
    filter_glob: StringProperty(default="*.fbx;*.glb;*.bvh", options={"HIDDEN"})
    format: EnumProperty(name="Format", default="FBX",
                         items=[("FBX", "FBX", ""), ("GLTF", "glTF (.glb)", ""), ("BVH", "BVH", "")])

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and active_rig(context) is not None

    def check(self, context):
        want = FORMATS[self.format]
        stem, ext = os.path.splitext(self.filepath)
        if ext.lower() != want:
            self.filepath = (stem if ext.lower() in FORMATS.values() else self.filepath) + want
            return True
        return False

    def invoke(self, context, event):
        self.format = context.scene.shapemove.export_format
        self.filename_ext = FORMATS[self.format]
        return super().invoke(context, event)

    def start(self, context):
        return f"wrote {export_rig(context, active_rig(context), self.filepath, self.format)}"


# -- preferences ---------------------------------------------------------------------------------
class SHAPEMOVE_OT_detect_python(ReportingOperator, bpy.types.Operator):
    """Find a Python with PyTorch for the ShapeMove jobs"""

    bl_idname = "shapemove.detect_python"
    bl_label = "Detect Python"

    def start(self, context):
        found = paths.detect_python()
        if not found:
            return "Blender's Python has PyTorch: jobs run inside Blender"
        prefs = preferences(context)
        if prefs is None:
            return None
        prefs.python_env = found
        return f"using {found}"


classes = (SHAPEMOVE_OT_build_from_motion, SHAPEMOVE_OT_generate, SHAPEMOVE_OT_cancel_job,
           SHAPEMOVE_OT_random_shape, SHAPEMOVE_OT_reset_shape, SHAPEMOVE_OT_shape_from_text, SHAPEMOVE_OT_measure,
           SHAPEMOVE_OT_redecode, SHAPEMOVE_OT_retarget, SHAPEMOVE_OT_library_search, SHAPEMOVE_OT_library_import,
           SHAPEMOVE_OT_train, SHAPEMOVE_OT_use_model, SHAPEMOVE_OT_export, SHAPEMOVE_OT_detect_python)
