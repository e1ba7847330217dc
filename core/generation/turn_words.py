"""Turning on the spot: the words say how far, the decoded body is turned that far.

The SA-VAE's tokens carry almost nothing of how fast the root turns: a linear probe from five
neighbouring codes to the root's yaw rate explains none of its variance on held-out clips, and
captured clips labelled "turn" that turn 3.2-13.5 rad come back from encoding and decoding turning
0.1-2.1 rad (``docs/codec.md``). So "a person turns around" steps on the spot without turning,
whoever writes the tokens. A prompt whose only action is a turn or a spin, or a turn beside one
gait ("walks forward and turns around": ``plan/reader.angle_of``), names the angle; the
decoded track is turned by it about the pelvis, eased in and out over the middle of the motion
(``TURN_SPAN``), and its feet are planted again, as for any edit:

- "turns around", "turns back", "about-face", "180": half a turn; "turns left" / "right", "a
  quarter turn": a quarter; "spins", "a full turn", "360", "all the way around": a whole turn;
  "twice" doubles it. Left (counter-clockwise seen from above) unless the words say right or
  clockwise.
- "turns his head", "turns the page": a part or a thing turns, not the body; "without turning
  around": no turn. Both are left alone.

    track = turned(track, read_words("a person turns around to the right").turn)   # plan/words.py
"""
from __future__ import annotations

import numpy as np

from .track import Track, headings, root_centre, rotate_y

TURN_SPAN = (0.2, 0.8)    # the share of the motion over which the body turns
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


def turn_motion(motion, body, angle: float | None, ik_refine_iters: int = 10):
    """A generated ``Motion`` turned by ``angle`` (radians, + = left: the plan's ``Words.turn``;
    ``track.replanted``: an edit, no tokens kept); the motion itself when it is None."""
    from .track import replanted, track_of

    return motion if angle is None else replanted(motion, body, turned(track_of(motion), angle), ik_refine_iters)
