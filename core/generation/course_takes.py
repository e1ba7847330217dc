"""A course walked by a capture of it: "a man walks in a figure eight" plays a captured figure eight.

The codec does not carry turning, so a course is a plain gait bent onto it (``course_walk.py``). Where
the takes that compete (``captured_takes.TakePool``: the built-in library's, the user's) hold takes of
the course's own action (the built-in CMU subject 105's figure eights: about 4.4 x 2 m, walked in
15-33 s, plainly and as a mummy; a user's captured circle), those takes compete with the samples of the
whole prompt (``Generator.choose``), and a take of the course that wins is played on its own path:

- whole when no length is asked (once round, as the take goes), else a window of the length asked,
  with a note saying how long once round takes;
- its first loop turned the way the plan says (``Words.course_right``: clockwise seen from above, or
  not), by its mirror image where it turns the other way (``first_turn_right``).

A course asked of another gait than the takes' ("jogs in a figure eight": ``OWN_GAITS``), an edited
plan, a stop or a turn, a timeline's segment (whole rounds in its time), or a take of the course that
loses to a sample: the gait is bent onto the course.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..constants import FPS
from ..plan.vocabulary import GAITS

OWN_GAITS = frozenset({"walk", "zombie walk"})   # the gaits the course's takes are walked in
FIRST_TURN = np.radians(45.0)                     # a turn this far is the first loop's way
HEADING_SPAN = 0.25                               # s: the path's heading over this (a step's sway smoothed)
MOVING = 0.2                                      # m/s: slower, the path has no heading


def first_turn_right(root, fps: float = FPS) -> bool | None:
    """Whether the path of ``root`` (T,3) (x, y, z; the body's left at +x when it faces +z) first
    turns right (clockwise seen from above) when its heading has gone ``FIRST_TURN`` from where it
    started; None when it never turns so far. The heading is the way the root goes over
    ``HEADING_SPAN`` s, where it goes at least ``MOVING`` m/s."""
    r = np.asarray(root, np.float64)[:, [0, 2]]
    k = max(1, int(round(HEADING_SPAN * fps)))
    d = r[k:] - r[:-k]
    d = d[np.linalg.norm(d, axis=1) >= MOVING * k / fps]
    if len(d) < 2:
        return None
    yaw = np.unwrap(np.arctan2(d[:, 0], d[:, 1]))   # + = toward +x: left
    far = np.flatnonzero(np.abs(yaw - yaw[0]) >= FIRST_TURN)
    return None if not len(far) else bool(yaw[far[0]] < yaw[0])


def course_take(gen, asked, words, course: str, whole: bool, body_of=None):
    """The ``Choice`` of a captured take of ``course`` for the request ``asked`` (its plan's
    ``words``), played as the module says, or None where the gait is to be bent onto the course.
    ``whole``: no length was asked; ``body_of``: the request whose words give the body."""
    pool = gen.pool if gen.captured_on else None
    if pool is None or course not in pool.actions:
        return None
    if (set(words.actions) & GAITS) - OWN_GAITS:   # "jogs in a figure eight": the takes walk it
        return None
    choice = gen.choose(dataclasses.replace(asked, seconds=None) if whole else asked, body_of=body_of)
    w = choice.window
    if w is None or w.action != course:
        return None
    i = pool.ids.index(w.clip_id)
    n = len(pool.take(i)["rotations"])
    note = ""
    if whole:   # once round: the take as it goes
        w = pool.window(i, n, asked.seed, asked=course)
    elif len(w.rotations) < n:
        note = (f"{len(w.rotations) / FPS:.1f} s of a captured {course.removeprefix('walk in a ')}, which goes once round in "
                f"{n / FPS:.1f} s (ask for that length, or none, to go round)")
    way = first_turn_right(w.root)
    if way is not None and way != bool(words.course_right):
        w = pool.mirrored_window(w)
    w = dataclasses.replace(w, provenance=w.provenance + ", on its own course")
    return choice._replace(window=w, note="; ".join(x for x in (choice.note, note) if x))
