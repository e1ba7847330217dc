"""The Animation sub-panel (View3D > Sidebar > ShapeMove > Animation): loop, root motion, a curve
to walk along, speed, and a timeline of prompts with durations (docs/animation.md).

Settings live on ``Scene.shapemove_animation``; the prompt, shape text and seed are the Generate
panel's. "Generate Animated" runs the worker's ``animate`` job, "Generate Timeline" its
``sequence`` job; the answer is built through the (undoable) build operator with the chosen root
motion. "Regenerate Strip" samples the active timeline rig's selected strip again (the other
segments keep their tokens) and re-applies the other strips' timing to the new rig, which then
replaces the old one (a failure leaves the old one untouched).
"""
from __future__ import annotations

import json

import bpy
import numpy as np
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty,
                       StringProperty)

from ..core.errors import ShapeMoveError
from ..core.scene.axes import points_to_y_up
from . import job_submit, paths
from .animation_rig import ROOT_MOTION_ITEMS, SEGMENTS_KEY, TRACK_NAME
from .operators import (JobOperator, ReportingOperator, build_rig_from_file, generation_params, keep_notes,
                        library_param, scene_prompt)
from .panels import _SettingsPanel, draw_job, draw_optional
from .redecode import MOTION_FILE_KEY
from .rig_state import PROVENANCE_KEY, current_betas, rig_of

MAX_CURVE_POINTS = 20_000


def _is_curve(self, obj):
    return obj.type == "CURVE"


class ShapeMoveTimelineItem(bpy.types.PropertyGroup):
    prompt: StringProperty(name="Prompt", default="a person walks forward")
    seconds: FloatProperty(name="Seconds", default=3.0, min=0.4, max=60.0, precision=1)


class ShapeMoveAnimationSettings(bpy.types.PropertyGroup):
    loop: BoolProperty(name="Loop", description="A cycle whose last frame flows into its first (Cycles modifier)")
    root_motion: EnumProperty(name="Root Motion", items=ROOT_MOTION_ITEMS, default="PELVIS")
    path_curve: PointerProperty(name="Path", type=bpy.types.Object, poll=_is_curve,
                                description="Walk along this curve (its length sets the duration unless Seconds is on)")
    speed: FloatProperty(name="Speed", default=1.0, min=0.5, max=2.0, description="Play slower or faster, feet re-planted")
    use_stretch: BoolProperty(name="Stretch", description="Stretch or squeeze the motion to a duration")
    stretch: FloatProperty(name="Duration", default=4.0, min=0.4, max=120.0, unit="TIME_ABSOLUTE")
    timeline: CollectionProperty(type=ShapeMoveTimelineItem)
    timeline_index: IntProperty(name="Segment", default=0)
    strip_index: IntProperty(name="Strip", default=1, min=1, description="The timeline segment to sample again (1-based)")


def curve_path(obj, context) -> list[list[float]]:
    """A curve object -> its points in world space as the path's [x, z] (metres, Y up)."""
    if obj is None or obj.type != "CURVE":
        raise ShapeMoveError("pick a curve object as the path")
    evaluated = obj.evaluated_get(context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    try:
        n = len(mesh.vertices)
        if n < 2:
            raise ShapeMoveError(f"curve {obj.name!r} has fewer than 2 points")
        if n > MAX_CURVE_POINTS:
            raise ShapeMoveError(f"curve {obj.name!r} has {n} points after its resolution; lower it")
        co = np.empty(3 * n, np.float64)
        mesh.vertices.foreach_get("co", co)
        # mesh vertices follow the curve's order for an open spline (one edge chain)
        edges = np.empty(2 * len(mesh.edges), np.int64)
        mesh.edges.foreach_get("vertices", edges)
    finally:
        evaluated.to_mesh_clear()
    mw = np.array(obj.matrix_world, np.float64)
    world = co.reshape(-1, 3) @ mw[:3, :3].T + mw[:3, 3]
    order = _chain(edges.reshape(-1, 2), n)
    yup = points_to_y_up(world[order])
    return yup[:, [0, 2]].tolist()


def _chain(edges: np.ndarray, n: int) -> np.ndarray:
    """Vertex order along an edge chain (starting at an end; vertex order without edges)."""
    if not len(edges):
        return np.arange(n)
    nbrs = [[] for _ in range(n)]
    for a, b in edges:
        nbrs[a].append(int(b))
        nbrs[b].append(int(a))
    start = next((i for i in range(n) if len(nbrs[i]) == 1), int(edges[0, 0]))
    order, prev, cur = [start], -1, start
    while True:
        nxt = [v for v in nbrs[cur] if v != prev and v not in order[-2:]]
        if not nxt or nxt[0] == start:
            break
        prev, cur = cur, nxt[0]
        order.append(cur)
    return np.asarray(order)


def _on_built(name: str, root_motion: str, replace=None, keep_strips=None):
    def done(msg):
        if msg.get("cancelled"):
            return None
        r = msg["result"]
        try:
            bpy.ops.shapemove.build_from_motion(filepath=str(r["path"]), rig_name=name, root_motion=root_motion)
        except RuntimeError as exc:
            from .jobs import report_error

            report_error(str(exc).replace("Error: ", "").strip())
            return None
        rig = rig_of(bpy.context.active_object)
        keep_notes(rig, r)   # a library clip played as captured
        if rig is not None and r.get("provenance"):   # "segment 2: captured: HDM05 ...; ..." of a timeline
            rig[PROVENANCE_KEY] = str(r["provenance"])
        if rig is not None and keep_strips:
            retime_strips(rig, keep_strips)
        if rig is not None and replace is not None and replace.name in bpy.data.objects:
            _remove_old(replace)
        return rig
    return done


def strip_timing(rig) -> list[tuple[float, float, float]]:
    """(frame_start, frame_end, scale) of each strip of a timeline rig."""
    anim = rig.animation_data
    track = anim.nla_tracks.get(TRACK_NAME) if anim is not None else None
    return [(s.frame_start, s.frame_end, s.scale) for s in track.strips] if track is not None else []


def retime_strips(rig, timing: dict) -> None:
    """Apply {strip index: (frame_start, frame_end, scale)} to a timeline rig's strips."""
    track = rig.animation_data.nla_tracks.get(TRACK_NAME)
    for i, (start, end, scale) in sorted(timing.items()):
        if i < len(track.strips):
            strip = track.strips[i]
            strip.scale = scale
            strip.frame_end = end
            strip.frame_start = start


def _remove_old(rig) -> None:
    body = rig.get("shapemove_body")
    for obj in (body, rig):
        if obj is not None and obj.name in bpy.data.objects:
            bpy.data.objects.remove(obj)


class SHAPEMOVE_OT_animate(JobOperator, bpy.types.Operator):
    """Generate the prompt with the animation settings: loop, root motion, path, speed (background job)"""

    bl_idname = "shapemove.animate"
    bl_label = "Generate Animated"
    job = "animate"

    def start(self, context):
        s, a = context.scene.shapemove, context.scene.shapemove_animation
        prompt = scene_prompt(context)
        params = {**generation_params(context, prompt), "prompt": prompt,
                  "seconds": s.seconds if s.use_seconds else None,
                  "loop": a.loop, "in_place": a.root_motion == "NONE",
                  "speed": a.speed if abs(a.speed - 1.0) > 1e-6 else None,
                  "stretch": a.stretch if a.use_stretch else None, **library_param(context)}
        if a.path_curve is not None:
            params["path"] = curve_path(a.path_curve, context)
        job_submit.submit_job("animate", params, kind=self.job, label="animate",
                              on_result=_on_built(paths.slug(prompt, 24), a.root_motion))
        return "generating..."


class SHAPEMOVE_OT_timeline_add(bpy.types.Operator):
    """Add a prompt to the timeline"""

    bl_idname = "shapemove.timeline_add"
    bl_label = "Add Prompt"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        a = context.scene.shapemove_animation
        item = a.timeline.add()
        item.prompt = context.scene.shapemove.prompt.strip() or item.prompt
        a.timeline_index = len(a.timeline) - 1
        return {"FINISHED"}


class SHAPEMOVE_OT_timeline_remove(bpy.types.Operator):
    """Remove the selected prompt from the timeline"""

    bl_idname = "shapemove.timeline_remove"
    bl_label = "Remove Prompt"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return len(context.scene.shapemove_animation.timeline) > 0

    def execute(self, context):
        a = context.scene.shapemove_animation
        a.timeline.remove(a.timeline_index)
        a.timeline_index = max(0, min(a.timeline_index, len(a.timeline) - 1))
        return {"FINISHED"}


class SHAPEMOVE_OT_sequence(JobOperator, bpy.types.Operator):
    """Generate the timeline of prompts as one motion with one NLA strip per prompt (background job)"""

    bl_idname = "shapemove.sequence"
    bl_label = "Generate Timeline"
    job = "sequence"

    def start(self, context):
        a = context.scene.shapemove_animation
        segs = [{"prompt": it.prompt.strip(), "seconds": float(it.seconds)} for it in a.timeline]
        if not segs:
            raise ShapeMoveError("the timeline is empty: add prompts with durations first")
        empty = [i + 1 for i, sg in enumerate(segs) if not sg["prompt"]]
        if empty:
            raise ShapeMoveError(f"timeline prompt {empty[0]} is empty")
        params = {**generation_params(context, "timeline"), "segments": segs,
                  "captured": bool(context.scene.shapemove.use_captured)}
        job_submit.submit_job("sequence", params, kind=self.job, label="timeline",
                              on_result=_on_built("Timeline", a.root_motion))
        return f"generating a timeline of {len(segs)} prompts..."


class SHAPEMOVE_OT_regenerate_strip(ReportingOperator, bpy.types.Operator):
    """Sample one strip of the active timeline rig again; the other strips keep their motion and timing"""

    bl_idname = "shapemove.regenerate_strip"
    bl_label = "Regenerate Strip"

    @classmethod
    def poll(cls, context):
        rig = rig_of(context.active_object)
        return rig is not None and bool(rig.get(SEGMENTS_KEY)) and not job_submit.running("sequence")

    def start(self, context):
        rig = rig_of(context.active_object)
        a = context.scene.shapemove_animation
        segments = json.loads(rig[SEGMENTS_KEY])
        k = a.strip_index - 1
        if not 0 <= k < len(segments):
            raise ShapeMoveError(f"strip {a.strip_index} does not exist: this timeline has {len(segments)}")
        source = rig.get(MOTION_FILE_KEY)
        if not source:
            raise ShapeMoveError("this rig does not know its motion file; generate the timeline again")
        timing = {i: t for i, t in enumerate(strip_timing(rig)) if i != k}
        params = {**generation_params(context, "timeline"), "regenerate": k, "motion": str(source),
                  "seed": int(context.scene.shapemove.seed) + 1000 + k,
                  "betas": [float(b) for b in current_betas(rig)],   # the body as the sliders left it
                  "captured": bool(context.scene.shapemove.use_captured)}
        context.scene.shapemove.seed += 1   # the next press samples another one
        job_submit.submit_job("sequence", params, kind="sequence", label="regenerate strip",
                              on_result=_on_built(rig.name, rig.get("shapemove_root_motion", "PELVIS"), replace=rig,
                                                  keep_strips=timing))
        return f"regenerating strip {k + 1}: {segments[k]['prompt']}"


class SHAPEMOVE_UL_timeline(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index=0):
        row = layout.row(align=True)
        row.prop(item, "prompt", text="", emboss=False)
        row.prop(item, "seconds", text="")


class SHAPEMOVE_PT_animation(_SettingsPanel, bpy.types.Panel):
    bl_label = "Animation"
    SETTINGS = "shapemove_animation"

    def draw_settings(self, context, a, col):
        col.prop(a, "root_motion")
        row = col.row(align=True)
        row.prop(a, "loop")
        row.prop(a, "speed")
        draw_optional(col, a, "use_stretch", "stretch")
        col.prop(a, "path_curve")
        draw_job(col, "animate", "shapemove.animate", "Generate Animated", icon="ANIM")
        col.separator()
        col.label(text="Timeline", icon="NLA")
        row = col.row()
        row.template_list("SHAPEMOVE_UL_timeline", "", a, "timeline", a, "timeline_index", rows=3)
        side = row.column(align=True)
        side.operator("shapemove.timeline_add", text="", icon="ADD")
        side.operator("shapemove.timeline_remove", text="", icon="REMOVE")
        draw_job(col, "sequence", "shapemove.sequence", "Generate Timeline", icon="SEQ_STRIP_DUPLICATE")
        rig = rig_of(context.active_object)
        if rig is not None and rig.get(SEGMENTS_KEY):
            row = col.row(align=True)
            row.prop(a, "strip_index")
            row.operator("shapemove.regenerate_strip", icon="FILE_REFRESH")


classes = (ShapeMoveTimelineItem, ShapeMoveAnimationSettings, SHAPEMOVE_OT_animate, SHAPEMOVE_OT_timeline_add,
           SHAPEMOVE_OT_timeline_remove, SHAPEMOVE_OT_sequence, SHAPEMOVE_OT_regenerate_strip, SHAPEMOVE_UL_timeline,
           SHAPEMOVE_PT_animation)


def register() -> None:
    bpy.types.Scene.shapemove_animation = PointerProperty(type=ShapeMoveAnimationSettings)


def unregister() -> None:
    del bpy.types.Scene.shapemove_animation
