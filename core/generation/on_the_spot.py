"""On the spot: a gait the words keep in place ("jogs in place", "marches on the spot") steps where
it stands.

The training data holds one caption of stepping in place, so every sample and retrieved clip of
"a person jogs in place" travels (the default model: 7.5-9.5 m in 4 s; `travel_words` can only set
aside candidates, and none stays). When a prompt names a gait (``part_prompts.LEGS``) and "in place"
or "on the spot" (``travel_words``), and the chosen motion's root still travels more than
``travel_words.SLACK`` (half a metre), its track is made to step on the spot
(``on_the_spot_track``):

- the root's horizontal path and each ankle's (and foot's) offset from the root, along the body's
  heading and square to it about its mean (the stance width), are scaled by the same factor
  ``s`` = ``SLACK`` / travel, so a planted foot stays planted (its place is the root's travel plus its
  offset, both scaled) and lands under the hip; heights and the upper body (carried by the root)
  are kept;
- each knee is placed again for its hip and its moved ankle with the leg's own bone lengths, bent
  forward (two-bone IK in the plane of the leg and the heading), so a lifted foot still lifts the
  knee instead of stretching the leg;

then the feet are planted again (``track.replanted``): an edit like a turn the words name
(``turn_words.py``), so the motion keeps no tokens. A loop of such a prompt is cut from its samples
stepped on the spot the same way, to ``LOOP_ALLOWED`` (``loop.generate_loop``).
"""
from __future__ import annotations

import numpy as np

from ..data.actions import action_spans
from .part_prompts import LEGS
from .travel_words import SLACK, travel_of

PELVIS = 0
LEGS_CHAINS = ((1, 4, 7, 10), (2, 5, 8, 11))   # hip, knee, ankle, foot: left, right
LOOP_ALLOWED = 0.1   # metres a loop's sample kept in place may travel (a cycle advances a few cm)


def asks_on_the_spot(prompt: str) -> bool:
    """Whether the prompt keeps a gait in place ("jogs in place", "marches on the spot")."""
    return travel_of(prompt).in_place and any(sp[2] in LEGS for sp in action_spans(prompt))


def _knee(hip: np.ndarray, ankle: np.ndarray, thigh: np.ndarray, shin: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """(T,3) knee for (T,3) hips and ankles and (T,) bone lengths, bent toward ``forward`` (T,3)."""
    d_vec = ankle - hip
    d = np.maximum(np.linalg.norm(d_vec, axis=1), 1e-6)
    u = d_vec / d[:, None]
    reach = np.minimum(d, thigh + shin - 1e-6)
    along = (thigh ** 2 - shin ** 2 + reach ** 2) / (2 * reach)
    side = np.sqrt(np.maximum(thigh ** 2 - along ** 2, 0.0))
    bend = forward - (forward * u).sum(1, keepdims=True) * u          # forward, square to the leg
    bend /= np.maximum(np.linalg.norm(bend, axis=1, keepdims=True), 1e-6)
    return hip + along[:, None] * u + side[:, None] * bend


def on_the_spot_track(joints: np.ndarray, scale: float) -> np.ndarray:
    """(T,22,3) joints whose root path and ankle offsets (along the heading; square to it, about the
    stance width) are ``scale`` times theirs (module doc); ``scale`` 1 gives the joints back."""
    from .track import headings

    J = np.asarray(joints, np.float64)
    if scale >= 1.0:
        return J.copy()
    h = headings(J)
    fwd = np.stack([np.sin(h), np.zeros_like(h), np.cos(h)], axis=1)      # (T,3) the heading, level
    left = np.stack([np.cos(h), np.zeros_like(h), -np.sin(h)], axis=1)     # (T,3) square to it, level
    root = J[:, PELVIS] * [1.0, 0.0, 1.0]
    moved = root[0] + scale * (root - root[0])                               # the root's path, scaled
    out = J + (moved - root)[:, None]                                       # the body carried by it
    for hip, knee, ankle, foot in LEGS_CHAINS:
        thigh = np.linalg.norm(J[:, knee] - J[:, hip], axis=1)
        shin = np.linalg.norm(J[:, ankle] - J[:, knee], axis=1)
        ahead = ((J[:, ankle] - root) * fwd).sum(1)                         # the ankle's offset along the heading
        aside = ((J[:, ankle] - root) * left).sum(1)                        # ... and square to it
        new_ankle = (out[:, ankle] - (1.0 - scale) * ahead[:, None] * fwd
                     - (1.0 - scale) * (aside - aside.mean())[:, None] * left)   # its stance width kept
        out[:, foot] += new_ankle - out[:, ankle]                           # the foot keeps its direction
        out[:, ankle] = new_ankle
        out[:, knee] = _knee(out[:, hip], new_ankle, thigh, shin, fwd)
    return out


def spot_track(track, prompt: str, allowed: float = SLACK):
    """``track`` (a ``track.Track``) stepping on the spot when ``prompt`` keeps a gait in place and
    the track travels more than ``allowed`` metres, scaled to travel that far; None otherwise (a
    loop allows ``LOOP_ALLOWED``: its advance repeats every cycle)."""
    from .track import Track, travel

    if not asks_on_the_spot(prompt) or len(track.joints) < 4:
        return None
    went = float(travel(track.joints)[-1])
    if went <= allowed:
        return None
    return Track(on_the_spot_track(track.joints, allowed / went), track.contacts)


def on_the_spot(motion, body, prompt: str, ik_refine_iters: int = 10):
    """``motion`` stepping on the spot (``spot_track``), feet planted again; the motion itself when
    the prompt does not keep a gait in place or it does not travel."""
    from .track import replanted, track_of

    spot = spot_track(track_of(motion), prompt)
    return motion if spot is None else replanted(motion, body, spot, ik_refine_iters)
