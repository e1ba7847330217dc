"""The plan of a prompt shown to people: as JSON (``generate --explain``, nothing generated) and as
one line per segment (what ``generate`` and ``demo`` print after generating).

    plan_json("a person walks forward, then sits down", seconds=6)
    -> {"prompt": ..., "seconds": 6.0, "segments": [
          {"text": "a person walks forward", "share": 0.5, "seconds": 3.0,
           "understood": {"actions": ["walk"], "travel": "forward"}},
          {"text": "a person sits down", "share": 0.5, "seconds": 3.0, "understood": {"actions": ["sit"]}}]}

A single segment's seconds are null when the length is the model's to choose.
"""
from __future__ import annotations

from .option_conflicts import option_notes
from .plan import plan_to_json, read_plan
from .reading import said


def plan_json(prompt: str, seconds: float | None = None, loop: bool = False, in_place: bool = False,
              path: bool = False, by_parts: bool = True, course_seconds=None) -> dict:
    """The plan of ``prompt`` (module doc), with the notes of the options it is asked with;
    ``by_parts`` False (``--no-parts``): the prompt whole, one segment, nothing read of its words;
    ``course_seconds``: a course segment's time to go once round (``plan.Plan.lengths``)."""
    if not by_parts:
        return {"prompt": str(prompt), "seconds": None if seconds is None else float(seconds),
                "segments": [{"text": str(prompt), "share": 1.0, "seconds": None if seconds is None else float(seconds),
                              "understood": {}}]}
    out = plan_to_json(read_plan(prompt, seconds), course_seconds)
    notes = option_notes(prompt, loop=loop, in_place=in_place, path=path)
    if notes:
        out["notes"] = notes
    return out


def plan_lines(prompt: str, motion=None, plan=None) -> list[str]:
    """One line per segment of ``prompt``'s plan (``plan``: an edited one): its text, its seconds (from
    ``motion``'s segments when it is a timeline of them) and what was understood of it."""
    plan = read_plan(prompt) if plan is None else plan
    if not plan.is_sequence:
        return [f"understood: {said(plan.segments[0].words.understood())}"]
    bounds = getattr(motion, "segment_bounds", None)
    spans = ([f"{(int(e) - int(s)) / motion.fps:.1f} s" for s, e in bounds]
             if bounds is not None and len(bounds) == len(plan.segments) else [f"{s.share:.0%}" for s in plan.segments])
    return [f"understood {i} of {len(plan.segments)} ({span}): {s.text!r}: {said(s.words.understood())}"
            for i, (s, span) in enumerate(zip(plan.segments, spans), 1)]
