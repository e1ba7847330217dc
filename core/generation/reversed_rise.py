"""Standing up from a seat: the sit before it played backwards.

The data hold no capture of standing up from a seat: the built-in library's get-ups (DeepMimic's
two) start lying on the floor, and the samples are decoded from their codes. So "a man sits down,
then stands up" sat on a chair, then went down on all fours to push himself up. In a timeline, a
segment whose words stand up (``get up``) right after one that sits down and ends seated (its
root down by ``posture_change.MIN_CHANGE`` of its highest, its head up: not ``lying``) is that sit
played backwards: it starts in the very pose the sit ends in, and the body rises the way it went
down. A segment shorter than the sit leaves out the sit's seated stretch (all but ``LEAD``
frames before the rise); a longer one holds the standing pose the sit started from for the rest. The segment says so (its provenance: "the sit of
segment 1, played backwards").

    if rises_from_seat(before_words, words, before_motion):
        motion = sit_reversed(before_motion, frames, 1)
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .posture_change import ENDS, LYING, MIN_CHANGE

HEAD = 15
SETTLED = 0.03   # m: the root within this of its seated height is still sitting
LEAD = 5         # frames of sitting kept before the rise


def ends_seated(joints) -> bool:
    """Whether (T, 22, 3) ``joints`` go down and end with the head up: the root's height at the end
    lower than at the start by ``MIN_CHANGE`` of its highest, the head's at the end above ``LYING``
    of its highest (a seat, a crouch; not the floor)."""
    j = np.asarray(joints, np.float64)
    if len(j) < 2 * ENDS:
        return False
    root, head = j[:, 0, 1], j[:, HEAD, 1]
    down = (root[:ENDS].mean() - root[-ENDS:].mean()) / max(root.max(), 1e-6)
    return bool(down >= MIN_CHANGE and head[-ENDS:].mean() > LYING * max(head.max(), 1e-6))


def rises_from_seat(before, words, before_motion) -> bool:
    """Whether a segment whose words are ``words`` (``plan.words.Words``) stands up from the seat the
    segment before (words ``before``, its finished ``before_motion``) ends on."""
    return bool(words.actions) and words.actions[0] == "get up" and "sit" in before.actions \
        and ends_seated(before_motion.joints)


def sit_reversed(sit, frames: int, index: int):
    """The finished ``sit`` Motion played backwards over ``frames`` frames (module docstring), as a
    segment's Motion (joints and contacts: what a stitched timeline joins); ``index``: the sit's
    segment, 1-based, for its provenance."""
    from ..motion.contacts import detect_contacts

    j = np.asarray(sit.joints)[::-1]
    c = np.asarray(sit.contacts if sit.contacts is not None and len(sit.contacts) == len(sit.joints)
                   else detect_contacts(sit.joints, sit.fps), np.uint8)[::-1]
    seated = j[0, 0, 1]
    rise = int(np.argmax(j[:, 0, 1] > seated + SETTLED)) if (j[:, 0, 1] > seated + SETTLED).any() else 0
    lo = max(0, min(rise - LEAD, len(j) - frames))   # a long sit's seated stretch left out, the rise kept
    j, c = j[lo:lo + frames], c[lo:lo + frames]
    extra = frames - len(j)
    if extra > 0:   # shorter than asked: the standing pose the sit started from, held
        j = np.concatenate([j, np.repeat(j[-1:], extra, 0)])
        c = np.concatenate([c, np.repeat(np.ones((1, c.shape[1]), np.uint8), extra, 0)])
    return dataclasses.replace(sit, joints=np.ascontiguousarray(j), contacts=np.ascontiguousarray(c), tokens=None,
                               features=None, provenance=f"the sit of segment {index}, played backwards",
                               retrieved_clips=[], notes=[], warnings=[])
