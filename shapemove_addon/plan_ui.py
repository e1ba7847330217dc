"""The plan of the prompt under it in the Generate panel: one box per segment with the fields the
user can change (text, action, side, course and its way, distance, count, seconds), before or after
generating; Generate (and generating again) uses the plan as edited.

"Read Plan" reads the prompt in this process (``core/plan``: pure Python, milliseconds); a
generation's answer shows the plan it was made from (the motion file's ``plan``). The fields are
put into the plan as read (``core/plan/panel_fields.py``) and sent to the worker with the job
(``jobs_shapemove.generate``'s "plan"), which checks it and names a wrong field. Editing the prompt
leaves the plan of the old one aside: Generate then reads the new prompt.
"""
from __future__ import annotations

import bpy

from ..core.errors import ShapeMoveError
from .operators import ReportingOperator
from .plan_fields import show_plan


def draw_plan(layout, s) -> None:
    """The plan's fields under the prompt (module doc), or the button that reads it."""
    row = layout.row(align=True)
    row.operator("shapemove.read_plan", icon="VIEWZOOM", text="Read Plan" if not s.plan_segments else "Read Again")
    if not s.plan_segments:
        return
    row.operator("shapemove.clear_plan", icon="X", text="")
    if s.plan_prompt.strip() != s.prompt.strip():
        layout.label(text="The prompt changed: Generate reads it anew", icon="INFO")
        return
    for n, item in enumerate(s.plan_segments, 1):
        box = layout.box()
        box.label(text=f"Segment {n} of {len(s.plan_segments)}" if len(s.plan_segments) > 1 else "Plan")
        box.prop(item, "text", text="")
        row = box.row(align=True)
        row.prop(item, "action")
        row.prop(item, "seconds")
        row = box.row(align=True)
        row.prop(item, "side", text="")
        row.prop(item, "course", text="")
        if item.course != "NONE":
            row.prop(item, "course_way", text="")
        row = box.row(align=True)
        row.prop(item, "distance")
        row.prop(item, "count")
        box.prop(item, "manner", text="")


class SHAPEMOVE_OT_read_plan(ReportingOperator, bpy.types.Operator):
    """Read the prompt into its plan: the segments in order and what each asks, as fields to change"""

    bl_idname = "shapemove.read_plan"
    bl_label = "Read Plan"

    def start(self, context):
        from ..core.generation.course_shapes import model_course_seconds
        from ..core.plan.explain import plan_json
        from .preferences import setting

        s = context.scene.shapemove
        prompt = s.prompt.strip()
        if not prompt:
            raise ShapeMoveError("the prompt is empty: describe a motion, e.g. 'a person jogs forward and waves'")
        once_round = model_course_seconds(setting("active_model") or None)   # a course's segment: once round
        show_plan(s, plan_json(prompt, s.seconds if s.use_seconds else None, course_seconds=once_round), prompt)
        n = len(s.plan_segments)
        return f"plan: {n} segment{'s' if n > 1 else ''}"


class SHAPEMOVE_OT_clear_plan(bpy.types.Operator):
    """Forget the plan: Generate reads the prompt as it is"""

    bl_idname = "shapemove.clear_plan"
    bl_label = "Clear Plan"

    def execute(self, context):
        s = context.scene.shapemove
        s.plan_segments.clear()
        s.plan_base = s.plan_prompt = ""
        return {"FINISHED"}


classes = (SHAPEMOVE_OT_read_plan, SHAPEMOVE_OT_clear_plan)
