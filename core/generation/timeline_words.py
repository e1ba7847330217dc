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
- a segment whose words name only gestures ("he waves", "raises the right hand": every action
  named is an arms action, ``plan.words.Words.gestures_only``) stands where it is: a sampled gesture
  that shuffles along (0.27 m over a 2 s wave on a tall body) is held to ``STILL_SLACK`` of travel;
- anything else 1.

The scale eases from one segment's to the next over ``EASE`` frames, so the feet do not jump at a
boundary. A segment that names a turn ("turns around", "turns left", "spins"; ``plan.words.Words.turn``)
turns the body that far over its own frames (what it turns by itself counted, eased as a single
prompt's turn) and every later segment goes on in the new direction: "walks forward" -> "turns
around" -> "walks forward" comes back. A segment that walks a course (a circle, a figure eight, back
and forth, a zigzag, a diagonal: ``plan.words.Words.course``) is turned along it over a whole number of the
course's periods fitted to its travel (``course_walk.course_turn``: a circle once round, its travel /
2 pi the radius; left first unless the words say clockwise or to the right), so it leaves the way the
course ends and the next segment goes on from there; one that barely travels (under
``CIRCLE_TRAVEL``) is left as it is. The feet are then planted as for any timeline.
"""
from __future__ import annotations

import numpy as np

from ..plan.words import read_words
from .on_the_spot import held_scale, spot_scale
from .pace_words import SLOW_SPEED
from .course_walk import course_turn
from .stride_scale import scaled_strides
from .track import headings, travel
from .turn_words import eased_turn, turned_by

EASE = 8   # frames over which the stride scale moves from one segment's to the next
CIRCLE_TRAVEL = 0.5   # m: a course segment that travels less is not bent
STILL_SLACK = 0.05    # m: the root travel a segment of gestures only keeps


def segment_scale(words, joints: np.ndarray) -> float:
    """The stride scale the plan's ``words`` (``plan.words.Words``) of one segment ask of its
    (T,22,3) joints (module doc)."""
    if words.in_place:
        return spot_scale(joints, True)
    if words.pace == "slow":
        return SLOW_SPEED
    if words.gestures_only:
        return held_scale(joints, STILL_SLACK)
    return 1.0


def turn_profile(joints: np.ndarray, bounds, prompts, readings=None) -> np.ndarray | None:
    """(T,) yaw each frame of a timeline is turned by so that every segment naming a turn or a circle
    turns that far and the segments after it keep the new heading; None when no segment does."""
    own = np.unwrap(headings(joints))
    phi = np.zeros(len(own))
    total, turns = 0.0, False
    readings = [read_words(p) for p in prompts] if readings is None else readings
    for (a, b), w in zip(np.asarray(bounds), readings):
        phi[a:] = total
        if b - a < 2:
            continue
        angle, course, turn = w.turn, w.course, None
        s = travel(joints[a:b]) if angle is None and course is not None else None
        if angle is not None:
            turn = eased_turn(own[a:b], angle)
        elif s is not None and s[-1] >= CIRCLE_TRAVEL:
            turn = course_turn(own[a:b], s, course, w.course_right)
        if turn is not None:
            phi[a:b] += turn
            total += turn[-1]
            phi[b:] = total
            turns = True
    return phi if turns else None


def worded_joints(joints: np.ndarray, bounds, prompts, readings=None) -> np.ndarray | None:
    """(T,22,3) joints of a timeline with each segment's strides scaled and turns made as its words
    ask (``bounds``: (S,2) frames, ``prompts``: S texts; ``readings``: the plan's reading of each, None
    for the text's own); None when no segment asks for anything."""
    J = np.asarray(joints, np.float64)
    scale = np.ones(len(J))
    readings = [read_words(p) if readings is None or readings[i] is None else readings[i]
                for i, p in enumerate(prompts)]
    for (a, b), w in zip(np.asarray(bounds), readings):
        scale[a:b] = segment_scale(w, J[a:b])
    phi = turn_profile(J, bounds, prompts, readings)
    if (scale >= 1.0).all() and phi is None:
        return None
    if (scale < 1.0).any():
        eased = np.convolve(np.pad(scale, EASE // 2, mode="edge"), np.ones(EASE) / EASE,
                            mode="same")[EASE // 2:-(EASE // 2)]
        J = scaled_strides(J, eased)
    return J if phi is None else turned_by(J, phi)
