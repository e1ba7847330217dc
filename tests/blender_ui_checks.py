"""Runs inside a fresh ``python`` with the bpy module (started by test_blender_ui.py): installs the
extension zip into a temporary user folder and exercises the ShapeMove panels and operators.
Usage: python blender_ui_checks.py CONFIG.json -> RESULTS.json.

Part 1 runs with torch made unimportable (Blender's Python usually lacks it): registering, panel
drawing, building an OpenBody rig from the numpy body, semantic sliders, Random/Reset, re-keying
a re-decoded motion, exports + re-imports, error reports. Part 2 lets torch import and runs jobs
through the in-process runner.

Panels are drawn with ``RnaLayout``: Blender as a module has no window to draw into (a real popup
crashes it), so each panel's real ``draw`` gets a layout object that checks every call against
Blender's RNA (the property exists on the data, the operator and its properties exist, icons are
valid names, UIList types are registered) and records what was drawn.
"""
from __future__ import annotations

import json
import os
import sys
import time
import traceback
from types import SimpleNamespace

import numpy as np

CONFIG = json.loads(open(sys.argv[1]).read())
os.environ["BLENDER_USER_RESOURCES"] = CONFIG["user_resources"]
os.environ["SHAPEMOVE_HOME"] = CONFIG["home"]
os.environ.pop("SHAPEMOVE_PYTHON", None)
sys.modules["torch"] = None  # part 1: `import torch` raises ImportError, as in a stock Blender

import bpy  # noqa: E402

RESULTS: dict = {"timings": {}}
ADDON = "bl_ext.user_default.shapemove"


MODELS = bool(CONFIG.get("model_dir"))  # the second run: jobs with trained (tiny) models


def timed(name, models: bool = False):
    """Run the section now (only in the run it belongs to) and record its time or its error."""
    def deco(fn):
        if name != "install" and models != MODELS:
            return fn
        t0 = time.perf_counter()
        try:
            fn()
        except Exception as exc:  # record, keep measuring the rest
            RESULTS.setdefault("errors", {})[name] = f"{exc}\n{traceback.format_exc()}"
        RESULTS["timings"][name] = time.perf_counter() - t0
        return fn
    return deco


def ext(name):
    import importlib

    return importlib.import_module(f"{ADDON}.{name}")


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
        cls.draw(SimpleNamespace(layout=RnaLayout(log)), context)
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


bpy.ops.wm.read_factory_settings(use_empty=False)  # the factory startup scene (cube, camera, light)
STATE: dict = {}


@timed("install")
def _install():
    r = bpy.ops.extensions.package_install_files(filepath=CONFIG["zip"], repo="user_default", enable_on_install=True)
    RESULTS["install"] = {"result": sorted(r), "enabled": ADDON in bpy.context.preferences.addons,
                          "panels": sorted(c.bl_idname for c in addon_panels() if hasattr(bpy.types, c.bl_idname)),
                          "torch_imported": isinstance(sys.modules.get("torch"), type(sys))}


@timed("draw_empty")
def _draw_empty():
    RESULTS["draw_empty"] = {"panels": draw_panels(), "preferences": draw_preferences(),
                             "active": bpy.context.active_object.name if bpy.context.active_object else None}


@timed("build")
def _build():
    res = RESULTS.setdefault("build", {})
    before = counts()
    r = bpy.ops.shapemove.build_from_motion(filepath=CONFIG["motion"], rig_name="Rig")
    rig = bpy.context.active_object
    STATE["rig"] = rig
    body = ext("core.scene.bodies").load_body("openbody-v1")
    res.update(result=sorted(r), new_objects=counts()["objects"] - before["objects"], rig=rig.name,
               body_type=type(body).__name__, has_tokens=bool(rig.get("shapemove_has_tokens")),
               motion_file=rig.get("shapemove_motion_file"), frames=keyed_frames(rig),
               torch_imported=isinstance(sys.modules.get("torch"), type(sys)))
    # the rig's bones sit on the numpy body's rest joints (Z-up)
    axes = ext("core.scene.axes")
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    motion = ext("core.scene.motion_file").load_motion(CONFIG["motion"])
    rest = axes.points_to_z_up(body.rest_joints(motion.betas)[0])
    res["rest_error_m"] = float(np.abs(bone_heads(rig, names) - rest).max())


@timed("draw_rig")
def _draw_rig():
    res = {"panels": draw_panels()}
    shape = res["panels"]["SHAPEMOVE_PT_shape"] or []
    res["semantic_props"] = [d["prop"] for d in shape if d["kind"] == "prop" and d["data"] == "ShapeMoveObjectProperties"]
    betas = res["panels"]["SHAPEMOVE_PT_shape_betas"] or []
    res["beta_props"] = [d["index"] for d in betas if d["kind"] == "prop" and d["prop"] == "betas"]
    RESULTS["draw_rig"] = res


@timed("apply_motion")
def _apply_motion():
    rig = STATE["rig"]
    mf = ext("core.scene.motion_file")
    axes = ext("core.scene.axes")
    names = list(ext("core.body.skeleton").JOINT_NAMES)[:22]
    m2 = mf.load_motion(CONFIG["motion2"])
    actions_before = len(bpy.data.actions)
    old_name = rig.animation_data.action.name
    ext("shapemove_addon.redecode").apply_motion(rig, m2)
    errs = []
    for k in (0, m2.num_frames // 2, m2.num_frames - 1):
        bpy.context.scene.frame_set(1 + k)
        errs.append(float(np.abs(posed_heads(rig, names) - axes.points_to_z_up(m2.joints[k])).max()))
    RESULTS["apply_motion"] = {"fk_error_m": max(errs), "actions_before": actions_before,
                               "actions_after": len(bpy.data.actions), "same_name": rig.animation_data.action.name == old_name,
                               "frames": keyed_frames(rig)}


@timed("semantic")
def _semantic():
    rig = STATE["rig"]
    sem = ext("shapemove_addon.semantic_shape")
    sync = ext("shapemove_addon.shape_sync")
    redecode = ext("shapemove_addon.redecode")
    body = sem.semantic_body(rig)
    res = {"names": body.phenotype_names}
    b0 = sync.current_betas(rig).copy()
    h0 = skeleton_height(rig)
    p0, w0 = rig.shapemove.height, rig.shapemove.weight
    rig.shapemove.height = p0 + 0.1  # the slider
    b1 = sync.current_betas(rig)
    res.update(height_before=h0, height_after=skeleton_height(rig), slider_before=p0, slider_after=rig.shapemove.height,
               betas_delta=(b1 - b0).tolist(),
               expected_delta=(0.1 * body.phenotype_matrix[body.phenotype_names.index("height")]).tolist(),
               weight_unchanged=abs(rig.shapemove.weight - w0) < 1e-6)
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    axes = ext("core.scene.axes")
    res["rest_error_m"] = float(np.abs(bone_heads(rig, names) - axes.points_to_z_up(body.rest_joints(b1)[0])).max())
    res["redecode_pending"] = sorted(redecode.pending())
    res["redecode_timer"] = bpy.app.timers.is_registered(redecode._fire)
    RESULTS["semantic"] = res


@timed("random_reset")
def _random_reset():
    rig = STATE["rig"]
    sync = ext("shapemove_addon.shape_sync")
    body = ext("shapemove_addon.semantic_shape").semantic_body(rig)
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    axes = ext("core.scene.axes")
    bpy.context.view_layer.objects.active = rig
    r1 = bpy.ops.shapemove.random_shape(seed=3)
    b_rand = sync.current_betas(rig).copy()
    err_rand = float(np.abs(bone_heads(rig, names) - axes.points_to_z_up(body.rest_joints(b_rand)[0])).max())
    r2 = bpy.ops.shapemove.reset_shape()
    b_reset = sync.current_betas(rig).copy()
    err_reset = float(np.abs(bone_heads(rig, names) - axes.points_to_z_up(body.joint_template)).max())
    RESULTS["random_reset"] = {"random": sorted(r1), "reset": sorted(r2), "betas_random": b_rand.tolist(),
                               "expected_random": np.clip(np.random.default_rng(3).normal(0, 1, 10), -5, 5).tolist(),
                               "rest_error_random_m": err_rand, "betas_reset": b_reset.tolist(),
                               "rest_error_reset_m": err_reset}


@timed("export")
def _export():
    rig = STATE["rig"]
    export = ext("shapemove_addon.export")
    res = {}
    for fmt, ext_ in export.FORMATS.items():
        path = os.path.join(CONFIG["export_dir"], "rig" + ext_)
        bpy.context.view_layer.objects.active = rig
        out = export.export_rig(bpy.context, rig, path, fmt)
        before = set(bpy.data.objects)
        if fmt == "FBX":
            bpy.ops.import_scene.fbx(filepath=str(out))
        elif fmt == "GLTF":
            bpy.ops.import_scene.gltf(filepath=str(out))
        else:
            bpy.ops.import_anim.bvh(filepath=str(out))
        new = [o for o in bpy.data.objects if o not in before]
        arm = next(o for o in new if o.type == "ARMATURE")
        res[fmt] = {"size": os.path.getsize(out), "bones": len(arm.data.bones),
                    "frames": keyed_frames(arm) if arm.animation_data and arm.animation_data.action else 0,
                    "meshes": sorted([len(o.data.vertices), len(o.data.shape_keys.key_blocks) if o.data.shape_keys else 0]
                                     for o in new if o.type == "MESH"),
                    "no_tmp": not any(f.endswith(".tmp" + ext_) for f in os.listdir(CONFIG["export_dir"]))}
        for o in new:
            bpy.data.objects.remove(o)
    res["rig_bones"], res["rig_frames"] = len(rig.data.bones), keyed_frames(rig)
    res["rig_vertices"] = len(ext("shapemove_addon.shape_sync").body_of(rig).data.vertices)
    # through the operator (Export panel)
    bpy.context.view_layer.objects.active = rig
    path = os.path.join(CONFIG["export_dir"], "op.bvh")
    res["operator"] = report_error(lambda: bpy.ops.shapemove.export(filepath=path, format="BVH"))
    res["operator_file"] = os.path.isfile(path)
    RESULTS["export"] = res


@timed("errors")
def _errors():
    res = {}
    before = counts()
    res["missing_file"] = report_error(lambda: bpy.ops.shapemove.build_from_motion(filepath=CONFIG["missing_motion"]))
    res["corrupt_file"] = report_error(lambda: bpy.ops.shapemove.build_from_motion(filepath=CONFIG["corrupt_motion"]))
    bpy.context.scene.shapemove.prompt = "   "
    res["empty_prompt"] = report_error(lambda: bpy.ops.shapemove.generate())
    s = bpy.context.scene.shapemove
    s.retarget_source, s.retarget_path = "FILE", CONFIG["missing_motion"]
    res["retarget_missing"] = report_error(lambda: bpy.ops.shapemove.retarget())
    s.train_data = CONFIG["missing_motion"]
    res["train_missing"] = report_error(lambda: bpy.ops.shapemove.train())
    res["counts_equal"] = before == counts()
    RESULTS["errors_reported"] = res


# -- part 2: torch imports, jobs run in this process -----------------------------------------------
del sys.modules["torch"]
import torch  # noqa: E402,F401


def run_jobs(timeout=120.0):
    """What Blender's timer does: poll the job manager until no job is left."""
    mgr = ext("shapemove_addon.jobs").manager()
    end = time.monotonic() + timeout
    while mgr.busy and time.monotonic() < end:
        mgr.poll()
        time.sleep(0.02)
    return not mgr.busy


@timed("measure_job")
def _measure_job():
    rig = STATE["rig"]
    jobs = ext("shapemove_addon.jobs")
    client = ext("core.worker.client")
    jobs.manager().set_runner(client.InProcessRunner())
    bpy.context.view_layer.objects.active = rig
    before = rig.shapemove.height_cm
    r = bpy.ops.shapemove.measure()
    running = ext("shapemove_addon.job_submit").running("measure")
    panels = draw_panels()
    progress = [d for d in panels["SHAPEMOVE_PT_shape"] if d["kind"] in ("progress", "operator") and
                d.get("op") in (None, "shapemove.cancel_job")]
    finished = run_jobs()
    RESULTS["measure_job"] = {"result": sorted(r), "running_after_submit": running, "finished": finished,
                              "height_before": before, "height_cm": rig.shapemove.height_cm,
                              "waist_cm": rig.shapemove.waist_cm, "betas": ext("shapemove_addon.shape_sync").current_betas(rig).tolist(),
                              "panel_while_running": progress,
                              "runner": type(jobs.manager().runner).__name__, "status": bpy.context.window_manager.shapemove_status}


@timed("shape_text_job")
def _shape_text_job():
    rig = STATE["rig"]
    bpy.context.view_layer.objects.active = rig
    bpy.context.scene.shapemove.shape_from_text = CONFIG["shape_text"]
    h0 = skeleton_height(rig)
    r = bpy.ops.shapemove.shape_from_text()
    finished = run_jobs()
    RESULTS["shape_text_job"] = {"result": sorted(r), "finished": finished, "height_cm": rig.shapemove.height_cm,
                                 "skeleton_before": h0, "skeleton_after": skeleton_height(rig),
                                 "betas": ext("shapemove_addon.shape_sync").current_betas(rig).tolist()}


@timed("dead_worker")
def _dead_worker():
    rig = STATE["rig"]
    prefs = bpy.context.preferences.addons[ADDON].preferences
    bpy.context.view_layer.objects.active = rig
    before = counts()
    h = rig.shapemove.height_cm
    prefs.python_env = os.path.join(CONFIG["home"], "no-such-python")
    res = {"missing_python": report_error(lambda: bpy.ops.shapemove.measure())}
    # a worker that starts and dies at once: the job ends with an error, the rig is untouched
    exe = os.path.join(CONFIG["home"], "dies.sh")
    with open(exe, "w") as f:
        f.write("#!/bin/sh\nexit 3\n")
    os.chmod(exe, 0o755)
    prefs.python_env = exe
    errors = []
    jobs = ext("shapemove_addon.jobs")
    res["submit"] = report_error(lambda: bpy.ops.shapemove.measure())
    job_id = next(iter(jobs.manager().jobs), None)
    if job_id is not None:
        jobs.manager().jobs[job_id].on_error = (lambda orig: (lambda msg: (errors.append(msg["message"]), orig(msg))))(
            jobs.manager().jobs[job_id].on_error)
    res["finished"] = run_jobs(timeout=30)
    res["job_errors"] = errors
    res["counts_equal"] = before == counts()
    res["height_unchanged"] = rig.shapemove.height_cm == h
    prefs.python_env = ""
    RESULTS["dead_worker"] = res


# -- run 2: generate, re-decode, search, import, train with tiny trained models ----------------------
def job_messages():
    """Record the error messages of the jobs that end in an error (instead of popups)."""
    errors: list = []
    jobs = ext("shapemove_addon.jobs")
    original = jobs.report_error
    jobs.report_error = lambda text: errors.append(text)
    return errors, lambda: setattr(jobs, "report_error", original)


@timed("generate", models=True)
def _generate():
    jobs, client = ext("shapemove_addon.jobs"), ext("core.worker.client")
    jobs.manager().set_runner(client.InProcessRunner())
    prefs = bpy.context.preferences.addons[ADDON].preferences
    prefs.active_model = CONFIG["model_dir"]
    s = bpy.context.scene.shapemove
    s.prompt, s.use_seconds, s.seconds, s.seed = "a person walks forward", True, 2.0, 1
    errors, restore = job_messages()
    before = set(bpy.data.objects)
    r = bpy.ops.shapemove.generate()
    finished = run_jobs()
    restore()
    new = [o for o in bpy.data.objects if o not in before]
    rig = next((o for o in new if o.type == "ARMATURE"), None)
    STATE["gen_rig"] = rig
    RESULTS["generate"] = {"result": sorted(r), "finished": finished, "errors": errors,
                           "new": sorted(o.type for o in new), "active_is_rig": bpy.context.active_object == rig,
                           "has_tokens": bool(rig and rig.get("shapemove_has_tokens")),
                           "frames": keyed_frames(rig) if rig else 0,
                           "height_cm": rig.shapemove.height_cm if rig else 0.0,
                           "data_dir": os.path.dirname(rig["shapemove_motion_file"]) if rig else ""}


@timed("redecode", models=True)
def _redecode():
    rig = STATE["gen_rig"]
    redecode = ext("shapemove_addon.redecode")
    sync = ext("shapemove_addon.shape_sync")
    bpy.context.view_layer.objects.active = rig
    rig.shapemove.betas[1] = float(rig.shapemove.betas[1] + 1.5)  # the slider
    pending = sorted(redecode.pending())
    errors, restore = job_messages()
    redecode._fire()  # what the debounce timer does
    finished = run_jobs()
    restore()
    path = rig.get("shapemove_redecoded_file")
    res = {"pending": pending, "finished": finished, "errors": errors, "file": path}
    if path:
        m = ext("core.scene.motion_file").load_motion(path)
        body = ext("core.scene.bodies").load_body(m.body_model)
        axes = ext("core.scene.axes")
        names = list(ext("core.body.skeleton").JOINT_NAMES)[:22]
        k = m.num_frames // 2
        bpy.context.scene.frame_set(1 + k)
        out = body.forward(torch.as_tensor(m.betas)[None], torch.as_tensor(m.poses[k:k + 1]),
                           torch.as_tensor(m.transl[k:k + 1]))
        res.update(fk_error_m=float(np.abs(posed_heads(rig, names) - axes.points_to_z_up(out.joints[0, :22].numpy())).max()),
                   betas_match=bool(np.abs(m.betas - sync.current_betas(rig)).max() < 1e-4),
                   tokens_match=bool(np.array_equal(m.tokens, ext("core.scene.motion_file").load_motion(
                       rig["shapemove_motion_file"]).tokens)))
    RESULTS["redecode"] = res


@timed("library", models=True)
def _library():
    s = bpy.context.scene.shapemove
    s.library_folder, s.library_query, s.library_top_k = CONFIG["dataset"], "a person walks", 3
    errors, restore = job_messages()
    r = bpy.ops.shapemove.library_search()
    finished = run_jobs()
    items = [(i.name, i.score, os.path.basename(i.path)) for i in s.library_results]
    panel = draw_panels()["SHAPEMOVE_PT_library"]
    before = set(bpy.data.objects)
    r2 = bpy.ops.shapemove.library_import(index=0)
    finished2 = run_jobs()
    restore()
    new = [o for o in bpy.data.objects if o not in before]
    rig = next((o for o in new if o.type == "ARMATURE"), None)
    RESULTS["library"] = {"search": sorted(r), "finished": finished, "items": items, "errors": errors,
                          "list_rows": [d["rows"] for d in panel if d["kind"] == "list"],
                          "import": sorted(r2), "import_finished": finished2, "new": sorted(o.type for o in new),
                          "rig_frames": keyed_frames(rig) if rig else 0}


@timed("retarget_action", models=True)
def _retarget_action():
    bpy.ops.import_anim.bvh(filepath=CONFIG["bvh"], update_scene_fps=False, update_scene_duration=False)
    src = bpy.context.active_object
    for o in bpy.context.view_layer.objects:
        o.select_set(o == src)
    s = bpy.context.scene.shapemove
    s.retarget_source, s.retarget_target = "ACTION", STATE["gen_rig"]
    errors, restore = job_messages()
    before = set(bpy.data.objects)
    r = bpy.ops.shapemove.retarget()
    finished = run_jobs()
    restore()
    new = [o for o in bpy.data.objects if o not in before]
    rig = next((o for o in new if o.type == "ARMATURE"), None)
    sync = ext("shapemove_addon.shape_sync")
    RESULTS["retarget_action"] = {
        "source": src.name, "source_type": src.type, "result": sorted(r), "finished": finished, "errors": errors,
        "new": sorted(o.type for o in new), "frames": keyed_frames(rig) if rig else 0,
        "betas_error": float(np.abs(sync.current_betas(rig) - sync.current_betas(STATE["gen_rig"])).max()) if rig else None,
        "bvh_written": sorted(f for f in os.listdir(os.path.dirname(STATE["gen_rig"]["shapemove_motion_file"]))
                              if f.endswith(".bvh"))}


@timed("train", models=True)
def _train():
    s = bpy.context.scene.shapemove
    s.train_data, s.train_kind, s.train_steps, s.train_config, s.train_model_name = \
        CONFIG["dataset"], "tma", 2, "tiny", "trained"
    errors, restore = job_messages()
    r = bpy.ops.shapemove.train(resume=False)
    running = ext("shapemove_addon.job_submit").running("train")
    finished = run_jobs(timeout=300)
    restore()
    r2 = report_error(lambda: bpy.ops.shapemove.use_model())
    prefs = bpy.context.preferences.addons[ADDON].preferences
    RESULTS["train"] = {"result": sorted(r), "running": running, "finished": finished, "errors": errors,
                        "train_result": s.train_result, "use": r2, "active_model": prefs.active_model,
                        "tma_file": os.path.isfile(os.path.join(s.train_result, "tma", "tma.pt")) if s.train_result else False}


with open(CONFIG["results"], "w") as f:
    json.dump(RESULTS, f, indent=1, default=float)
# bpy 4.2 crashes at exit after any glTF export (a Blender bug): the results are written, leave now
sys.stdout.flush()
sys.stderr.flush()
os._exit(0)
