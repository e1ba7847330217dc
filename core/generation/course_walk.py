"""Walking a course the words name: a circle, a figure eight, back and forth, a zigzag, a diagonal. The words
say the path, the feet keep their steps.

The SA-VAE's tokens do not carry how fast the root turns. Real circle walks and jogs of the
training data turn 0.6-1.05 rad/s; the same clips encoded and decoded by the shipped codec turn
0.06-0.23 rad/s, so "walks around in a circle" comes out as a straight walk whether the T5 writes
it or a captured circle is retrieved (measured in ``docs/prompts.md``). The prompt names the path,
so the path is given: the decoded track is walked along the course (``polyline.follow_track``:
the body keeps its steps, sway and limbs; its course is bent and the feet are planted again), as a
path drawn by the user would be.

A course is one heading profile over a period of it and the period's length for a motion that
travels so far (``course_shapes.Course``, ``COURSES``; the shapes and times, free of torch, are
there). A single prompt walks the profile repeated (``course_line``); a
timeline's segment walks a whole number of periods fitted to its own travel (``course_turn``), so
the next segment goes on the way the course leaves it. Left first unless the words say "clockwise"
(not "counter-" or "anti-clockwise") or "to the right":

- ``CIRCLE`` ("walks around in a circle"): once round, radius ``radius_for`` (the travel / 2 pi,
  within ``MIN_RADIUS`` .. ``MAX_RADIUS``).
- ``EIGHT`` ("walks in a figure eight", "a figure-8 path"): two circles touching where the walk
  starts, once round one way, then once round the other; each loop's radius lets the motion go
  once round the whole eight.
- ``BACK_AND_FORTH`` ("walks back and forth", "paces the room"): out, a U-turn of ``U_RADIUS``,
  back along a line ``2 U_RADIUS`` aside, a U-turn: once out and back over the motion's travel
  (legs of ``LEG_MIN`` .. ``LEG_MAX``).
- ``ZIGZAG`` ("zigzags across the yard"): legs of ``ZIG`` metres alternately ``ZIG_ANGLE`` to
  either side of the way the walk goes, turning between them over ``ZIG_TURN`` of a leg.
- ``DIAGONAL`` ("walks diagonally to the right", "runs off at an angle"): ``DIAGONAL_ANGLE`` to the
  named side (left unless it says right), turned to over the first ``DIAGONAL_EASE`` metres; in a
  timeline the segments after it go on that way.
- ``ASIDE`` ("runs to the left", "jogs off to her right"): a quarter turn to the named side over the
  first ``ASIDE_EASE`` metres, then on that way; each "to the left / right" turns from the way the
  walker goes ("runs to the left, then to the right": left, then on as at the start).

The gait is generated without the course's words when the rest still names one ("a person walks in
a figure eight" -> "a person walks"; "paces", "zigzags" -> "walks"; ``plan.reader.straight_gait``): the captured
circles and eights the model learnt them from turn, and decoded without their turning they walk at
0.3-0.6 m/s (a plain walk 1.1 m/s), so a 10 s eight went half round one loop. A motion that does
not travel (a wave, a sit, "rocks back and forth") is left as it is.

With no length asked, a course is given the time to go once round at its gait's typical pace
(``course_shapes.course_seconds``: a circle walked 5.8 s, jogged 4.5 s; a figure eight walked 11.7
s), not the model's own length (a retrieved 2.6 s walk goes a quarter of an eight), in a timeline's
segment too ("walks a loop around the tree, then waves": 5.8 s, then 3 s); a length asked that is
too short to go round is noted (``course_note``).

    w = read_words("a woman walks around in a circle, waving")     # plan/words.py
    track = on_course(track, w.course, w.course_right)
"""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from .course_shapes import CIRCLE, COURSES, NOTE_BELOW, ROUND, STEP, round_share, whole_period
from .polyline import MIN_SPEED, Polyline, follow_track
from .track import Track, motion_speed, travel


def course_note(course: str | None, joints, fps: float = FPS) -> str | None:
    """A note for the user when the motion is too short to go once round its course (a figure eight
    asked for 4 s), with the length that would; None otherwise."""
    share = round_share(course, float(travel(joints)[-1]))
    if share is None or share >= NOTE_BELOW:
        return None
    seconds = len(joints) / fps
    return (f"{seconds:.1f} s goes {share:.0%} of the way round the {ROUND[course]}: once round takes about "
            f"{seconds / share:.0f} s at this pace (ask for that length to go round)")


def course_line(distance: float, course: str, right: bool, whole: bool = False) -> Polyline:
    """``course`` from the origin, heading +Z, as long as ``distance`` metres need (at least one
    period and a quarter more): its heading integrated every ``STEP`` m. ``whole``: a whole number
    of periods (at least one) fitted to ``distance``, as a timeline's segment walks it, so the next
    segment goes on the way the course leaves."""
    c = COURSES[course]
    period = whole_period(course, distance) if whole and distance > 0 else c.period_for(distance)
    s = np.arange(0.0, max(distance, period) + period / 4 + STEP, STEP)
    yaw = c.yaw(s, period, right)
    mid = (yaw[1:] + yaw[:-1]) / 2
    xz = np.concatenate([[[0.0, 0.0]], np.cumsum(np.stack([np.sin(mid), np.cos(mid)], axis=1) * STEP, axis=0)])
    return Polyline(xz)


def course_turn(own: np.ndarray, s: np.ndarray, course: str, right: bool) -> np.ndarray:
    """(n,) yaw added to a timeline segment whose own heading is ``own`` (n,) and whose travel is
    ``s`` (n,) metres from its start: the course over a whole number of periods fitted to its travel
    (at least one), what it turns by itself taken out evenly along its travel."""
    c = COURSES[course]
    total = max(float(s[-1]), 1e-6)
    period = whole_period(course, total)
    return c.yaw(s, period, right) - (own[-1] - own[0]) * np.asarray(s, np.float64) / total


def on_course(track: Track, course: str | None, right: bool = False, fps: float = FPS, whole: bool = False) -> Track:
    """``track`` walked along ``course`` (the plan's, or the action of the nearest known caption;
    None: a circle), clockwise when ``right``; unchanged when it does not travel. ``whole``: whole
    periods fitted to its travel (``course_line``)."""
    if motion_speed(track.joints, fps) < MIN_SPEED:
        return track
    return follow_track(track, course_line(float(travel(track.joints)[-1]), course or CIRCLE, right, whole), crop=False)


def course_motion(motion, body, course: str | None, right: bool = False, ik_refine_iters: int = 10,
                  whole: bool = False):
    """A generated ``Motion`` walked along ``course`` (as ``on_course``; ``track.replanted``: an edit,
    no tokens kept); the motion itself when it does not travel. Unless ``whole`` (a timeline's
    segment: whole rounds), a motion too short to go once round says so (``course_note``)."""
    from .track import replanted, track_of

    tr = track_of(motion)
    bent = on_course(tr, course, right, motion.fps, whole)
    out = motion if bent is tr else replanted(motion, body, bent, ik_refine_iters)
    note = None if whole else course_note(course, out.joints, out.fps)
    if note:   # "a figure eight" in 4 s goes a third of the way round
        out.notes.append(note)
    return out
