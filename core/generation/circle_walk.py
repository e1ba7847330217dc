"""Walking in a circle: the words say the path, the feet keep their steps.

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
- A motion that does not travel (a wave, a sit) is left as it is.

    track = circled(track, "a woman walks around in a circle, waving")
"""
from __future__ import annotations

import re

import numpy as np

from ..data.actions import find_actions
from ..constants import FPS
from .polyline import MIN_SPEED, Polyline, follow_track
from .track import Track, motion_speed, travel

CIRCLE = "walk in a circle"
MIN_RADIUS, MAX_RADIUS = 1.0, 3.0   # m
CLOCKWISE = re.compile(r"(?<![-\w])(?:clockwise|to the right|rightward)\b")
COUNTER = re.compile(r"\b(?:counter|anti)[- ]?clockwise\b")


def names_circle(text: str) -> bool:
    """Whether the words ask for walking (or running) in a circle."""
    return CIRCLE in find_actions(text)


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


def circled(track: Track, text: str, fps: float = FPS) -> Track:
    """``track`` walked along the circle ``text`` asks for; unchanged when it does not travel."""
    if motion_speed(track.joints, fps) < MIN_SPEED:
        return track
    return follow_track(track, circle_line(float(travel(track.joints)[-1]), turns_right(text)), crop=False)


def circle_motion(motion, body, text: str, ik_refine_iters: int = 10):
    """A generated ``Motion`` walked along the circle ``text`` asks for (``track.replanted``: an
    edit, no tokens kept); the motion itself when it does not travel."""
    from .track import replanted, track_of

    tr = track_of(motion)
    bent = circled(tr, text, motion.fps)
    return motion if bent is tr else replanted(motion, body, bent, ik_refine_iters)
