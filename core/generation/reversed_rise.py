"""Standing up from a seat or a crouch: the segment before it played backwards.

The data hold no capture of standing up from a seat: the built-in library's get-ups (DeepMimic's
two) start lying on the floor, and the samples are decoded from their codes. So "a man sits down,
then stands up" sat on a chair, then went down on all fours to push himself up. In a timeline, a
segment whose words only stand up (``get up``) right after one that sits down and ends seated (its
root down by ``posture_change.MIN_CHANGE`` of its highest, its head up: not ``lying``) is that sit
played backwards: it starts in the very pose the sit ends in, and the body rises the way it went
down, its seated stretch left out (all but ``LEAD`` frames before the rise) and, once up, the
standing pose the sit started from held for the rest of the segment.

A squat or a bend before a stand-up ("squats, holds it, then stands up"; ``LOWERED``) goes down and
up again as captured, so it is held from its lowest frame on (``held_low``) and the stand-up rises
from there the same way. The segment says so (its provenance: "segment 1 played backwards").

    if rises_from_seat(before_words, words, before_motion):
        motion = sit_reversed(before_motion, contacts, frames, 1)
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..body.skeleton import JOINT_NAMES
from ..plan.vocabulary import RISEN_FROM
from .captured_takes import without_last_pose_held
from .posture_change import ENDS, LYING, MIN_CHANGE, height_change

HEAD = JOINT_NAMES.index("head")
LOWERED = frozenset({"sit"}) | RISEN_FROM   # a seat, a squat, a bend: what a stand-up after it rises from
SETTLED = 0.03   # m: the root within this of its seated height is still sitting
LEAD = 5         # frames of sitting kept before the rise


def ends_seated(joints) -> bool:
    """Whether (T, 22, 3) ``joints`` go down and end with the head up: the root's height at the end
    lower than at the start by ``MIN_CHANGE`` of its highest, the head's at the end above ``LYING``
    of its highest (a seat, a crouch; not the floor)."""
    j = np.asarray(joints, np.float64)
    if len(j) < 2 * ENDS:
        return False
    head = j[:, HEAD, 1]
    return bool(-height_change(j[:, 0, 1]) >= MIN_CHANGE and head[-ENDS:].mean() > LYING * max(head.max(), 1e-6))


def stands_up(words) -> bool:
    """Whether a segment's words (``plan.words.Words``) ask only to stand up."""
    return list(words.actions) == ["get up"]


def lowers(words) -> bool:
    """Whether a segment's words ask to sit or to go down and up again (``LOWERED``: a squat, a bend)."""
    return any(a in LOWERED for a in words.actions)


def lies_from_seat(before, words, before_motion) -> bool:
    """Whether a segment whose words only lie down follows one that sits (``before``) and ends seated
    (its finished ``before_motion``): it goes on from the seat (``Request.seated``)."""
    return list(words.actions) == ["lie down"] and "sit" in before.actions and ends_seated(before_motion.joints)


def rises_from_seat(before, words, before_motion) -> bool:
    """Whether a segment whose words are ``words`` (``plan.words.Words``) stands up from the seat the
    segment before (words ``before``, its finished ``before_motion``) ends on."""
    return stands_up(words) and lowers(before) and ends_seated(before_motion.joints)


def held_low(motion, contacts):
    """A finished segment that goes down (its (T, 4) foot ``contacts``) held from its lowest frame on
    (the root's lowest), so the segment after it can stand up from there: "squats, holds it, then
    stands up" (a captured squat goes down and up again). The Motion itself when it is lowest at its
    end already."""
    j = np.asarray(motion.joints)
    low = int(np.argmin(j[:, 0, 1]))
    if (j[low:, 0, 1] - j[low, 0, 1]).max() < SETTLED:   # it stays down to its end already
        return motion
    c = np.asarray(contacts, np.uint8)
    held = len(j) - low - 1
    return dataclasses.replace(
        motion, joints=np.concatenate([j[:low + 1], np.repeat(j[low:low + 1], held, 0)]),
        contacts=np.concatenate([c[:low + 1], np.repeat(c[low:low + 1], held, 0)]), tokens=None, features=None,
        notes=without_last_pose_held(motion.notes)   # held low instead
        + [f"held at its lowest from {low / motion.fps:.1f} s: the next segment stands up"])


def played_backwards(index: int) -> str:
    """The provenance of a segment that is segment ``index`` (1-based) played backwards."""
    return f"segment {index} played backwards"


def sit_reversed(sit, contacts, frames: int, index: int):
    """The finished ``sit`` Motion (its (T, 4) foot ``contacts``) played backwards over ``frames``
    frames (module docstring), as a segment's Motion (joints and contacts: what a stitched timeline
    joins); ``index``: the sit's segment, 1-based, for its provenance."""
    j = np.asarray(sit.joints)[::-1]
    c = np.asarray(contacts, np.uint8)[::-1]
    seated = j[0, 0, 1]
    rise = int(np.argmax(j[:, 0, 1] > seated + SETTLED)) if (j[:, 0, 1] > seated + SETTLED).any() else 0
    lo = max(0, rise - LEAD)   # the seated stretch left out but LEAD frames: the rise comes first
    j, c = j[lo:lo + frames], c[lo:lo + frames]
    extra = frames - len(j)
    if extra > 0:   # shorter than asked: the standing pose the sit started from, held
        j = np.concatenate([j, np.repeat(j[-1:], extra, 0)])
        c = np.concatenate([c, np.repeat(np.ones((1, c.shape[1]), np.uint8), extra, 0)])
    return dataclasses.replace(sit, joints=np.ascontiguousarray(j), contacts=np.ascontiguousarray(c), tokens=None,
                               features=None, provenance=played_backwards(index),
                               retrieved_clips=[], notes=[], warnings=[])
