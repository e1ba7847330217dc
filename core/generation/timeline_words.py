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
boundary; the feet are then planted as for any timeline.
"""
from __future__ import annotations

import numpy as np

from .on_the_spot import asks_on_the_spot, spot_scale
from .pace_words import SLOW_SPEED, asks_slow_flight, asks_slow_steps
from .stride_scale import scaled_strides

EASE = 8   # frames over which the stride scale moves from one segment's to the next


def segment_scale(prompt: str, joints: np.ndarray) -> float:
    """The stride scale the words of one segment ask of its (T,22,3) joints (module doc)."""
    if asks_on_the_spot(prompt):
        return spot_scale(joints, prompt)
    if asks_slow_steps(prompt) or asks_slow_flight(prompt):
        return SLOW_SPEED
    return 1.0


def worded_joints(joints: np.ndarray, bounds, prompts) -> np.ndarray | None:
    """(T,22,3) joints of a timeline with each segment's strides scaled as its words ask (``bounds``:
    (S,2) frames, ``prompts``: S texts); None when no segment asks for anything."""
    J = np.asarray(joints, np.float64)
    scale = np.ones(len(J))
    for (a, b), prompt in zip(np.asarray(bounds), prompts):
        scale[a:b] = segment_scale(prompt, J[a:b])
    if (scale >= 1.0).all():
        return None
    eased = np.convolve(np.pad(scale, EASE // 2, mode="edge"), np.ones(EASE) / EASE, mode="same")[EASE // 2:-(EASE // 2)]
    return scaled_strides(J, eased)
