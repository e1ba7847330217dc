"""Which request wins where the prompt's words and the animation options cannot both be honoured,
said as notes (``Motion.notes``, printed by the command line as ``note:`` lines).

- ``--loop`` repeats one cycle that comes back to its own facing and never stops: it wins over a
  course ("in a circle"), a named turn ("turns around"), a stop or a distance ("walks 3 metres and
  stops"), and over segments in order ("walks, then sits": the prompt is looped as one motion);
- ``--path`` sets where the body goes: it wins over a course and a named turn;
- ``--in-place`` removes the root's travel: it wins over a course's travel (its turning is kept)
  and over a distance;
- ``--seconds`` sets the length: it wins over a length the words ask ("jogs for ten seconds"), and
  so does ``--loop`` (one cycle).
"""
from __future__ import annotations

from .plan import read_plan
from .reading import course_said


def option_notes(prompt: str, loop: bool = False, in_place: bool = False, path: bool = False,
                 seconds: float | None = None) -> list[str]:
    """One note per request of ``prompt`` that an option overrides (module doc); [] when none does."""
    if not (loop or in_place or path or seconds is not None):
        return []
    plan = read_plan(prompt)
    notes = []
    said = [s.words.seconds for s in plan.segments if s.words.seconds is not None]
    asked = " + ".join(f"{x:g} s" for x in said)
    if loop and said:
        notes.append(f"--loop won over the {asked} the words ask: a loop is one cycle, played for as long as the "
                     "scene runs (leave out --loop for that length)")
    elif seconds is not None and said and (plan.is_sequence or abs(said[0] - seconds) > 1e-6):
        notes.append(f"--seconds {seconds:g} won over the {asked} the words ask (leave out --seconds for theirs)")
    if loop and plan.is_sequence:
        notes.append(f"--loop won over the order of {len(plan.segments)} motions: the prompt is looped as one motion "
                     "(leave out --loop for one after the other)")
    for reading in (s.words.understood() for s in plan.segments):
        if loop and "course" in reading:
            notes.append(f"--loop won over '{course_said(reading)}': a loop repeats one straight cycle "
                         "(leave out --loop to walk the course)")
        if loop and "turn_degrees" in reading:
            notes.append(f"--loop won over the turn of {reading['turn_degrees']} degrees: a loop comes back to its "
                         "own facing (leave out --loop to keep the turn)")
        if loop and (reading.get("stop") or "distance_m" in reading):
            notes.append("--loop won over the stop: a loop never stops (leave out --loop to stop)")
        if path and "course" in reading:
            notes.append(f"--path won over '{course_said(reading)}': the body walks your path")
        if path and "turn_degrees" in reading:
            notes.append(f"--path won over the turn of {reading['turn_degrees']} degrees: the body faces along your path")
        if in_place and "course" in reading:
            notes.append(f"--in-place won over '{course_said(reading)}': its travel is removed, its turning kept")
        if in_place and "distance_m" in reading:
            notes.append(f"--in-place won over the distance of {reading['distance_m']:g} m: the travel is removed")
    return list(dict.fromkeys(notes))
