"""Walking in a circle or a figure eight: the words say the path, the feet keep their steps.

The SA-VAE's tokens do not carry how fast the root turns. Real circle walks and jogs of the
training data turn 0.6-1.05 rad/s; the same clips encoded and decoded by the shipped codec turn
0.06-0.23 rad/s, so "walks around in a circle" comes out as a straight walk whether the T5 writes
it or a captured circle is retrieved (measured in ``docs/prompts.md``). The prompt names the path,
so the path is given: the decoded track is walked along a circle (``polyline.follow_track``:
the body keeps its steps, sway and limbs; its course is bent onto the circle and the feet are
planted again), as a path drawn by the user would be.

- The circle turns left (counter-clockwise seen from above) unless the words say "clockwise" (not
  "counter-" or "anti-clockwise") or "to the right"; its radius lets the motion go round once
  (``radius_for``: the track's travel / 2 pi, kept within ``MIN_RADIUS`` .. ``MAX_RADIUS``).
- A figure eight ("walks in a figure eight", "a figure-8 path") is two such circles, touching where
  the walk starts: once round to the left, then once round to the right (or the other way round for
  "clockwise"), again as long as the motion travels (``eight_line``; each loop's radius lets the
  motion go once round the whole eight). Before, the eight was walked straight.
- The gait is generated without the course's words when the rest still names one ("a person walks
  in a figure eight" -> "a person walks"; ``straight_gait``): the captured circles and eights the
  model learnt them from turn, and decoded without their turning they walk at 0.3-0.6 m/s (a plain
  walk 1.1 m/s), so a 10 s eight went half round one loop.
- A motion that does not travel (a wave, a sit) is left as it is.

    track = circled(track, "a woman walks around in a circle, waving")
    track = circled(track, "a man walks in a figure eight")
"""
from __future__ import annotations

import re

import numpy as np

from ..data.actions import find_actions
from ..data.compose_parts import LEGS_ACTIONS
from ..constants import FPS
from .polyline import MIN_SPEED, Polyline, follow_track
from .track import Track, motion_speed, travel

CIRCLE = "walk in a circle"
EIGHT = "walk in a figure eight"
COURSES = (CIRCLE, EIGHT)            # the actions whose words name the course walked
MIN_RADIUS, MAX_RADIUS = 1.0, 3.0   # m
CLOCKWISE = re.compile(r"(?<![-\w])(?:clockwise|to the right|rightward)\b")
# the course in words: "in a circle", "around in circles", "a figure-8 path", "along a figure-eight route"
COURSE_WORDS = re.compile(r"(?:\s+(?:around|round|along|on|in|into|through|doing|making|tracing))*\s+(?:(?:a|an|the)\s+)?"
                          r"(?:(?:small|big|large|wide|tight|full)\s+)?(?:figure[- ]?(?:of[- ])?(?:8|eight)|circles?)"
                          r"(?:[- ]shaped)?(?:\s+(?:path|route|pattern|course|shape|loop))?\b", re.I)
TURN_WAY = re.compile(r"\s+(?:(?:counter|anti)[- ]?)?clockwise\b|\s+(?:to the (?:right|left)|rightwards?|leftwards?)\b",
                      re.I)   # the course's way round, not the gait's ("runs in a circle to the right")
COUNTER = re.compile(r"\b(?:counter|anti)[- ]?clockwise\b")


def names_circle(text: str) -> bool:
    """Whether the words ask for walking (or running) in a circle."""
    return CIRCLE in find_actions(text)


def names_eight(text: str) -> bool:
    """Whether the words ask for walking (or running) a figure eight."""
    return EIGHT in find_actions(text)


def course_named(text: str) -> str | None:
    """``EIGHT`` or ``CIRCLE`` when the words name that course (the eight first: "a figure eight"
    is not a circle), else None."""
    return EIGHT if names_eight(text) else CIRCLE if names_circle(text) else None


def straight_gait(text: str) -> tuple[str, str] | None:
    """(the words without the course they name and its way round, the gait left in them) --
    "someone jogs in a figure eight clockwise, waving" -> ("someone jogs, waving", "jog") -- or None
    when no course phrase is found or what is left names no gait ("goes around in a circle")."""
    if not COURSE_WORDS.search(str(text)):
        return None
    straight = re.sub(r"\s+([,.;])", r"\1", TURN_WAY.sub("", COURSE_WORDS.sub("", str(text)))).strip()
    gaits = [a for a in find_actions(straight) if a in LEGS_ACTIONS and a not in COURSES]
    return (straight, gaits[0]) if gaits else None


def walked_straight(text: str) -> str:
    """The words a course's gait is sampled from (``straight_gait``'s), else ``text`` itself."""
    gait = straight_gait(text)
    return gait[0] if gait else text


def turns_right(text: str) -> bool:
    """Clockwise seen from above: "clockwise", "to the right" (not "counter-clockwise")."""
    t = str(text).lower()
    return bool(CLOCKWISE.search(COUNTER.sub(" ", t)))


def radius_for(distance: float) -> float:
    """The radius (m) of a circle once round in ``distance`` metres, within MIN..MAX_RADIUS."""
    return float(np.clip(distance / (2 * np.pi), MIN_RADIUS, MAX_RADIUS))


def circle_line(distance: float, right: bool) -> Polyline:
    """A circle from the origin, heading +Z, turning left (or right) with ``radius_for(distance)``,
    long enough for ``distance`` metres (at least once round)."""
    r = radius_for(distance)
    turns = max(1.0, distance / (2 * np.pi * r)) + 0.25
    a = np.linspace(0.0, 2 * np.pi * turns, max(64, int(256 * turns)))
    sign = -1.0 if right else 1.0           # +X is the body's left when it faces +Z (SMPL)
    x = sign * r * (1.0 - np.cos(a))
    z = r * np.sin(a)
    return Polyline(np.stack([x, z], axis=1))


def eight_line(distance: float, right: bool) -> Polyline:
    """A figure eight from the origin, heading +Z: loops of ``radius_for(distance / 2)`` turning
    left (or right) first, then the other way, alternating, long enough for ``distance`` metres
    (at least once round the eight). The loops touch at the origin, where the heading is +Z again:
    each is ``circle_line``'s circle, on alternate sides."""
    r = radius_for(distance / 2)
    loops = max(2.0, distance / (2 * np.pi * r)) + 0.25
    a = np.linspace(0.0, 2 * np.pi * loops, max(128, int(256 * loops)))
    side = np.where((a // (2 * np.pi)) % 2 == 0, 1.0, -1.0) * (-1.0 if right else 1.0)   # +X: the body's left
    return Polyline(np.stack([side * r * (1.0 - np.cos(a)), r * np.sin(a)], axis=1))


def course_line(distance: float, course: str, right: bool) -> Polyline:
    """The line of ``course`` (``EIGHT``, else a circle) for ``distance`` m, turning right first
    when ``right``."""
    return (eight_line if course == EIGHT else circle_line)(distance, right)


def circled(track: Track, text: str, fps: float = FPS, course: str | None = None) -> Track:
    """``track`` walked along the circle or figure eight ``text`` asks for (``course``, when given,
    says which: the caller may have read it from the nearest known caption; else the words', else a
    circle); unchanged when it does not travel."""
    if motion_speed(track.joints, fps) < MIN_SPEED:
        return track
    course = course or course_named(text) or CIRCLE
    return follow_track(track, course_line(float(travel(track.joints)[-1]), course, turns_right(text)), crop=False)


def circle_motion(motion, body, text: str, ik_refine_iters: int = 10, course: str | None = None):
    """A generated ``Motion`` walked along the circle or figure eight ``text`` asks for (``course``:
    as ``circled``; ``track.replanted``: an edit, no tokens kept); the motion itself when it does
    not travel."""
    from .track import replanted, track_of

    tr = track_of(motion)
    bent = circled(tr, text, motion.fps, course)
    return motion if bent is tr else replanted(motion, body, bent, ik_refine_iters)
