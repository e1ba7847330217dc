"""A timeline's segments obey their pace and travel words: "jogs in place" steps on the spot and
"walks slowly" slows down inside a timeline too.

A single prompt's word edits (``on_the_spot.py``, ``slow_steps.py``) drop the motion's tokens; a
timeline keeps its tokens (Regenerate Strip, re-decoding for a new body), so its edits are made
where its track is made, every time (``sequence._planted``: generation, Regenerate Strip and
``sequence.redecode_timeline``). Each segment gets a stride scale (``stride_scale.scaled_strides``:
the root's path and the feet's reach shortened together, the frames and cadence kept):

- a gait kept in place that travels more than ``travel_words.SLACK`` over its segment: ``SLACK`` /
  its travel;
- a gait asked slowly (a walk as a jog: within a timeline the frames stay where the strips put
  them, so a walk too takes shorter strides rather than being played slower): ``SLOW_SPEED``;
- anything else 1.

The scale eases from one segment's to the next over ``EASE`` frames, so the feet do not jump at a
boundary. A segment that names a turn ("turns around", "turns left", "spins"; ``turn_words.angle_of``)
turns the body that far over its own frames (what it turns by itself counted, eased as a single
prompt's turn) and every later segment goes on in the new direction: "walks forward" -> "turns
around" -> "walks forward" comes back. A segment that walks in a circle (``circle_walk.course_named``)
turns a whole turn at an even rate over its frames, so its course goes once round (its travel / 2 pi
the radius; left unless the words say clockwise or to the right); one that walks a figure eight
(``circle_walk.names_eight``) turns a whole turn that way over the first half of its frames and
back over the second, so its course goes round one loop and then the other and it leaves facing as
it came; one that barely travels (under ``CIRCLE_TRAVEL``) is left as it is. The feet are then planted as for any timeline.
"""
from __future__ import annotations

import numpy as np

from .on_the_spot import asks_on_the_spot, spot_scale
from .pace_words import SLOW_SPEED, asks_slow_flight, asks_slow_steps
from .circle_walk import EIGHT, course_named, turns_right
from .stride_scale import scaled_strides
from .track import headings, travel
from .turn_words import angle_of, eased_turn, turned_by

EASE = 8   # frames over which the stride scale moves from one segment's to the next
CIRCLE_TRAVEL = 0.5   # m: a circle segment that travels less is not bent round


def segment_scale(prompt: str, joints: np.ndarray) -> float:
    """The stride scale the words of one segment ask of its (T,22,3) joints (module doc)."""
    if asks_on_the_spot(prompt):
        return spot_scale(joints, prompt)
    if asks_slow_steps(prompt) or asks_slow_flight(prompt):
        return SLOW_SPEED
    return 1.0


def turn_profile(joints: np.ndarray, bounds, prompts) -> np.ndarray | None:
    """(T,) yaw each frame of a timeline is turned by so that every segment naming a turn or a circle
    turns that far and the segments after it keep the new heading; None when no segment does."""
    own = np.unwrap(headings(joints))
    phi = np.zeros(len(own))
    total, turns = 0.0, False
    for (a, b), prompt in zip(np.asarray(bounds), prompts):
        phi[a:] = total
        if b - a < 2:
            continue
        angle, course, turn = angle_of(prompt), course_named(prompt), None
        if angle is not None:
            turn = eased_turn(own[a:b], angle)
        elif course is not None and travel(joints[a:b])[-1] >= CIRCLE_TRAVEL:
            turn = course_turn(own[a:b], course == EIGHT, turns_right(prompt))
        if turn is not None:
            phi[a:b] += turn
            total += turn[-1]
            phi[b:] = total
            turns = True
    return phi if turns else None


def course_turn(own: np.ndarray, eight: bool, right: bool) -> np.ndarray:
    """(n,) yaw added to a segment whose own heading is ``own`` (n,) so that it goes once round a
    circle at an even rate, or round a figure eight (a whole turn one way over the first half, back
    over the second), left first unless ``right``; what it turns by itself is taken out evenly."""
    u = np.arange(len(own)) / (len(own) - 1)
    whole = -2 * np.pi if right else 2 * np.pi
    target = whole * (1.0 - np.abs(1.0 - 2.0 * u)) if eight else whole * u
    return target - (own[-1] - own[0]) * u


def worded_joints(joints: np.ndarray, bounds, prompts) -> np.ndarray | None:
    """(T,22,3) joints of a timeline with each segment's strides scaled and turns made as its words
    ask (``bounds``: (S,2) frames, ``prompts``: S texts); None when no segment asks for anything."""
    J = np.asarray(joints, np.float64)
    scale = np.ones(len(J))
    for (a, b), prompt in zip(np.asarray(bounds), prompts):
        scale[a:b] = segment_scale(prompt, J[a:b])
    phi = turn_profile(J, bounds, prompts)
    if (scale >= 1.0).all() and phi is None:
        return None
    if (scale < 1.0).any():
        eased = np.convolve(np.pad(scale, EASE // 2, mode="edge"), np.ones(EASE) / EASE,
                            mode="same")[EASE // 2:-(EASE // 2)]
        J = scaled_strides(J, eased)
    return J if phi is None else turned_by(J, phi)
