"""The plan's fields in the scene settings (``properties.ShapeMovePlanSegment``) and back: a plan
(``--explain``'s JSON) shown as fields, and the plan as the user edited them, for a generate job
(``core/plan/panel_fields.py`` does the conversion; ``plan_ui.py`` draws them)."""
from __future__ import annotations

import json

from ..core.plan.panel_fields import edited_plan, plan_fields


def show_plan(s, plan: dict, prompt: str) -> None:
    """Put ``plan`` (``--explain``'s JSON) into the scene settings ``s`` as fields, read from ``prompt``."""
    s.plan_segments.clear()
    for f in plan_fields(plan):
        item = s.plan_segments.add()
        item.text, item.action = f["text"], f["action"]
        item.side = f["side"] or "NONE"
        item.course = f["course"] or "NONE"
        item.course_way = f["course_way"]
        item.distance, item.count, item.seconds = f["distance"], f["count"], f["seconds"]
        item.manner = f["manner"] or "NONE"
    s.plan_base = json.dumps(plan)
    s.plan_prompt = prompt


def _fields(s) -> list[dict]:
    return [{"text": i.text.strip(), "action": i.action.strip(), "side": "" if i.side == "NONE" else i.side,
             "course": "" if i.course == "NONE" else i.course, "course_way": i.course_way,
             "distance": round(float(i.distance), 3), "count": int(i.count), "seconds": round(float(i.seconds), 3),
             "manner": "" if i.manner == "NONE" else i.manner}
            for i in s.plan_segments]


def plan_param(s) -> dict:
    """{"plan": JSON} of the edited plan when one is shown for the current prompt, else {}."""
    if not s.plan_segments or not s.plan_base or s.plan_prompt.strip() != s.prompt.strip():
        return {}
    try:
        base = json.loads(s.plan_base)
    except ValueError:
        return {}
    return {"plan": json.dumps(edited_plan(base, _fields(s)))}
