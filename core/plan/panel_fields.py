"""The fields of a plan the panel shows under the prompt, and the plan they make once edited.

    fields = plan_fields(plan_json("a man walks 3 metres forward, then waves", 4))
    -> [{"text": "a man walks 3 metres forward", "action": "walk", "side": "", "course": "",
         "course_way": "left", "distance": 3.0, "count": 0, "seconds": 2.0, "manner": ""},
        {... "action": "wave" ...}]
    edited_plan(plan, fields)   # the plan's JSON with the fields' values, for ``plan.plan_from_json``

A field's empty value asks nothing: side "" (no side), course "", distance 0, count 0, manner ""
(none: the plain takes); seconds 0
is the segment's share of the length (a length its words asked, "for ten seconds", included). The other readings of a segment (its travel, a turn, a
pace, two things at once) are kept as the words gave them.
"""
from __future__ import annotations

import copy

SIDES = ("", "left hand", "right hand", "left foot", "right foot")


def plan_fields(plan: dict) -> list[dict]:
    """One dict of panel fields per segment of ``plan`` (``--explain``'s JSON)."""
    out = []
    for seg in plan["segments"]:
        said = seg.get("understood", {})
        actions = said.get("actions") or []
        out.append({"text": seg["text"], "action": actions[0] if actions else "",
                    "side": said.get("side", ""), "course": said.get("course") or "",
                    "course_way": said.get("course_way", "left"), "distance": float(said.get("distance_m") or 0.0),
                    "count": int(said.get("count") or 0), "seconds": float(seg.get("seconds") or 0.0),
                    "manner": said.get("manner") or ""})
    return out


def edited_plan(plan: dict, fields: list[dict]) -> dict:
    """``plan`` (``--explain``'s JSON) with each segment's panel ``fields`` put in (module doc)."""
    if len(fields) != len(plan["segments"]):
        from ..errors import ShapeMoveError

        raise ShapeMoveError(f"the plan has {len(plan['segments'])} segments, the panel {len(fields)}: read the plan again")
    out = copy.deepcopy(plan)
    out.pop("notes", None)
    for seg, f in zip(out["segments"], fields):
        said = seg.setdefault("understood", {})
        seg["text"] = f["text"]
        actions = list(said.get("actions") or [])
        if f["action"] and (not actions or actions[0] != f["action"]):
            said["actions"] = [f["action"]]
        elif not f["action"]:
            said.pop("actions", None)
        for key, value in (("side", f["side"]), ("course", f["course"]), ("manner", f.get("manner", ""))):
            if value:
                said[key] = value
            else:
                said.pop(key, None)
        if f["course"]:
            said["course_way"] = f["course_way"]
        else:
            said.pop("course_way", None)
        if f["distance"] > 0:
            said["distance_m"], said["stop"] = float(f["distance"]), True
        elif "distance_m" in said:
            del said["distance_m"]
            if "steps" not in said:
                said.pop("stop", None)
        if f["count"] > 0:
            said["count"] = int(f["count"])
        else:
            said.pop("count", None)
        seg["seconds"] = float(f["seconds"]) if f["seconds"] > 0 else None
        if f["seconds"] <= 0:   # the segment's share: the length its words asked goes too
            said.pop("seconds", None)
    if all(seg["seconds"] is not None for seg in out["segments"]):
        out["seconds"] = round(sum(seg["seconds"] for seg in out["segments"]), 3)
    return out
