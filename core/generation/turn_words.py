"""Turning on the spot: the words say how far, the decoded body is turned that far.

The SA-VAE's tokens carry almost nothing of how fast the root turns: a linear probe from five
neighbouring codes to the root's yaw rate explains none of its variance on held-out clips, and
captured clips labelled "turn" that turn 3.2-13.5 rad come back from encoding and decoding turning
0.1-2.1 rad (``docs/codec.md``). So "a person turns around" steps on the spot without turning,
whoever writes the tokens. A prompt whose only action is a turn or a spin names the angle; the
decoded track is turned by it about the pelvis, eased in and out over the middle of the motion
(``TURN_SPAN``), and its feet are planted again, as for any edit:

- "turns around", "turns back", "about-face", "180": half a turn; "turns left" / "right", "a
  quarter turn": a quarter; "spins", "a full turn", "360", "all the way around": a whole turn;
  "twice" doubles it. Left (counter-clockwise seen from above) unless the words say right or
  clockwise.
- "turns his head", "turns the page": a part or a thing turns, not the body; "without turning
  around": no turn. Both are left alone.

    track = turned(track, angle_of("a person turns around to the right"))
"""
from __future__ import annotations

import re

import numpy as np

from ..data.actions import find_actions, specific
from .track import Track, headings, root_centre, rotate_y

TURN_SPAN = (0.2, 0.8)    # the share of the motion over which the body turns
WHOLE = re.compile(r"\b(?:spins?|spinning|full (?:turn|circle|rotation)|360|all the way (?:a)?round|pirouettes?)\b")
HALF = re.compile(r"\b(?:turns? (?:a)?round|turning (?:a)?round|turns? back|turning back|about[- ]face|u-turn|180|"
                  r"face the other way|the other direction)\b")
QUARTER = re.compile(r"\b(?:quarter turn|90|turns? (?:to (?:the|his|her|their) )?(?:left|right)|turning (?:to the )?(?:left|right))\b")
RIGHT = re.compile(r"\b(?:right|clockwise|rightward)\b")
COUNTER = re.compile(r"\b(?:counter|anti)[- ]?clockwise\b")
NOT_BODY = re.compile(r"\bturn(?:s|ing|ed)? (?:his|her|their|the|its|one's|a) (?!body\b|whole\b)\w+")
TWICE = re.compile(r"\b(?:twice|two times|two full)\b")
NEGATED = re.compile(r"\b(?:without|not|no|never|don't|doesn't|do not|does not|stop)\s+(?:\w+\s+)?(?:turn|spin)")


def angle_of(text: str) -> float | None:
    """The yaw (radians, + = left) a prompt of one turn or spin asks the body to turn; None when
    the prompt asks for something else too, turns a part or a thing, or names no amount."""
    t = " " + str(text).lower() + " "
    acts = set(specific(find_actions(t)))
    if not acts or not acts <= {"turn", "spin"} or NOT_BODY.search(t) or NEGATED.search(t):
        return None
    if WHOLE.search(t) or "spin" in acts:
        a = 2 * np.pi
    elif HALF.search(t):
        a = np.pi
    elif QUARTER.search(t):
        a = np.pi / 2
    else:
        return None
    if TWICE.search(t):
        a *= 2
    right = bool(RIGHT.search(COUNTER.sub(" ", t)))
    return float(-a if right else a)


def eased_turn(own: np.ndarray, angle: float) -> np.ndarray:
    """(T,) yaw to add to frames whose own unwrapped heading is ``own`` so that over them the body
    turns ``angle`` in all (what it turns by itself is counted), eased (smoothstep) over
    ``TURN_SPAN`` of the frames."""
    n = len(own)
    u = np.clip((np.arange(n) / max(n - 1, 1) - TURN_SPAN[0]) / (TURN_SPAN[1] - TURN_SPAN[0]), 0.0, 1.0)
    return (angle - (own[-1] - own[0])) * u * u * (3 - 2 * u)


def turned_by(joints: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """(T,22,3) ``joints`` with frame t turned by ``phi[t]`` about the pelvis's smoothed course, the
    course's own steps turned with it, so a walk that turns around walks back rather than on
    backwards."""
    J = np.asarray(joints, np.float64)
    n = len(J)
    c = root_centre(J)
    old = np.stack([c[:, 0], np.zeros(n), c[:, 1]], axis=1)              # (T,3) the course, on the floor
    new = old[:1] + np.vstack([np.zeros((1, 3)), np.cumsum(rotate_y(np.diff(old, axis=0), phi[1:]), axis=0)])
    return rotate_y(J - old[:, None], phi) + new[:, None]


def turned(track: Track, angle: float) -> Track:
    """``track`` turned so that over its length it turns ``angle`` in all (``eased_turn``,
    ``turned_by``). The contacts are the track's (planting follows)."""
    phi = eased_turn(np.unwrap(headings(track.joints)), angle)
    return Track(turned_by(track.joints, phi), track.contacts)


def turn_motion(motion, body, text: str, ik_refine_iters: int = 10):
    """A generated ``Motion`` turned as far as ``text`` says (``track.replanted``: an edit, no
    tokens kept); the motion itself when the text names no turn of the body."""
    from .track import replanted, track_of

    angle = angle_of(text)
    return motion if angle is None else replanted(motion, body, turned(track_of(motion), angle), ik_refine_iters)
