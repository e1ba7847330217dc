"""What a timeline's plan says of its segments, read back from the motion it was made from.

A timeline made from a plan (``plan/plan.py``; edited or not) keeps it (``Motion.plan``). When one
of its segments is regenerated, the other segments' edited fields (an action, a side, a count the
user set) must still hold, so they are read from that plan rather than from the segments' words
again (``sequence.regenerate_segment``, ``stitched_timeline.regenerate_stitched``).
"""
from __future__ import annotations

from ..errors import ShapeMoveError
from ..scene.motion_file import Motion


def plan_readings(motion: Motion) -> list | None:
    """The readings of a timeline's segments in the plan it was made from (``Motion.plan``, an edited
    plan's fields kept), None without one or when it does not match the segments."""
    if not motion.plan or motion.segment_prompts is None:
        return None
    from ..plan.plan import plan_from_json

    try:
        plan = plan_from_json(motion.plan)
    except ShapeMoveError:
        return None
    if [s.text for s in plan.segments] != list(motion.segment_prompts):
        return None
    return [s.words for s in plan.segments]
