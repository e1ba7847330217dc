"""Sitting down, played from a captured lie-down: no take of the data sits down, every lie-down does
on its way to the floor.

The archives hold no capture of sitting down (HDM05's ``sitDown*`` classes are not among them), and
the T5 writes none the plan can trust: "an old man sits down slowly" walked 9 m (a retrieved elderly
walk), "a man sits down on a chair" bobbed into a crouch and back up. Every one of HDM05's 18
``lieDownFloor`` takes sits on the floor first, the pelvis 0.13-0.25 m high and the head 0.6-0.8 m,
the trunk upright, before it leans back to lie. So when the words ask to sit, a lie-down take
competes as a sit: played from its start to the middle of its sitting stretch (``sit_end``), then
held on that pose. It sits on the floor; there is no chair in the scene to sit on.

A frame sits when its pelvis is low (at most ``LOW`` of the take's highest) and its trunk is up
(the head at least ``UPRIGHT`` of the standing head-to-pelvis height above the pelvis). The pelvis
goes on down while the body sits (from 0.3 m to 0.11-0.25 m), so the sit ends where it is lowest
in the first sitting stretch, the trunk still at 0.75-0.91 of its standing height: measured on the
18 takes, 1.1-3.8 s into the take. There 12 of them have settled, a heel or toe on the floor (a
foot joint within ``SETTLED`` leg lengths of it: 0.03-0.12 m); the other six still hold the feet
up (0.13-0.19 m) and are not offered: held there with the feet free, the legs of a sit played as
the legs of two things at once were pulled 14 cm by the planting.

A lie-down asked right after a segment that ends seated (``Request.seated``) plays such a take from
where it sits to its end: the body goes on from the seat instead of standing up to lie down.

    end = sit_end(joints)        # frames of the take to play, or None: it never sits
"""
from __future__ import annotations

import numpy as np

from ..body.skeleton import FOOT_LEFT, FOOT_RIGHT, JOINT_NAMES
from ..motion.skeleton_ops import leg_length

LOW = 0.35        # a sitting pelvis is at most this share of the take's highest
SETTLED = 0.15    # ... and a foot joint within this many leg lengths of the floor where it ends
UPRIGHT = 0.75    # ... with the head this share of the standing head-to-pelvis height above it
HEAD = JOINT_NAMES.index("head")
FEET = FOOT_LEFT + FOOT_RIGHT   # ankles and feet
SIT_FROM = "lie down"   # the action whose takes sit on their way down
SIT = "sit"


def sitting(joints) -> np.ndarray:
    """(T,) bool: the frames of (T, J, 3) joints (y up) that sit (module doc)."""
    j = np.asarray(joints, dtype=np.float64)
    root, head = j[:, 0, 1], j[:, HEAD, 1]
    standing = max(float(np.max(head[:5] - root[:5])), 1e-6)
    return (root <= LOW * max(float(root.max()), 1e-6)) & (head - root >= UPRIGHT * standing)


def sit_end(joints) -> int | None:
    """How many frames of a lie-down take to play for a sit: up to the frame of its first sitting
    stretch where the pelvis is lowest; None when no frame sits, or when the body has not settled
    there (no foot joint within ``SETTLED`` leg lengths of the floor)."""
    s = sitting(joints)
    if not s.any():
        return None
    j = np.asarray(joints, dtype=np.float64)
    first = int(np.argmax(s))
    after = np.flatnonzero(~s[first:])
    last = first + (int(after[0]) if len(after) else len(s) - first)
    end = first + int(np.argmin(j[first:last, 0, 1])) + 1
    return end if j[end - 1, FEET, 1].min() <= SETTLED * leg_length(j) else None
