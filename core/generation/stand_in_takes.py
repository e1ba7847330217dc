"""Actions no captured take is of, played from the takes of another: a sit from a lie-down, played
to where it sits on the floor (``floor_sit.py``); a pick-up from a put-down played backwards.

The archives hold no capture of sitting down nor of picking something up, and the T5 writes
neither reliably. HDM05's 20 ``depositFloorR`` takes bend down, set something on the floor with the
right hand and stand up again; played backwards they bend down, take it from the floor and stand
up: a pick-up, every contact of the feet where it was (time reversed, a planted foot stays
planted). A put-down walks up to the spot and away again, which backwards steps back twice; so
where its feet hold still through the whole bend (``bend_span``: no foot moves faster than
``STEPPING`` from before the hand goes down to after it comes back up, the right wrist at both ends
of that stretch higher than halfway from its lowest to its highest), that stretch plays backwards,
and a take without one does not stand in (as a lie-down that never settles on the floor does not
sit). So when the words ask one of these actions and no take is of it, the takes of
``STAND_IN`` compete for it, made into it (``stand_in_span``, ``played_as``), each saying how ("captured: HDM05 bd
depositFloorR 004 (CC BY-SA 3.0), its bend played backwards").

    span = stand_in_span("pick up", "put down", joints)   # the frames that play it (joints: the take posed), or None
    rot, root, con, action, said = played_as("pick up", rot, root, con, span)
"""
from __future__ import annotations

import numpy as np

from ..body.skeleton import FOOT_LEFT, FOOT_RIGHT, JOINT_NAMES
from ..constants import FPS
from ..motion.skeleton_ops import gaussian_smooth
from .floor_sit import SIT, SIT_FROM, sit_end

PICK_UP, PUT_DOWN = "pick up", "put down"
STAND_IN = {SIT: SIT_FROM, PICK_UP: PUT_DOWN}   # an action no take is of: the action whose takes play it
STEPPING = 0.5     # m/s: a foot joint moving faster than this (lightly smoothed) takes a step
RIGHT_WRIST, FOOT_JOINTS = JOINT_NAMES.index("right_wrist"), sorted(FOOT_LEFT + FOOT_RIGHT)


def bend_span(joints, fps: float = FPS) -> tuple[int, int] | None:
    """(start, end) frames of a put-down's (T, J, 3) ``joints`` (y up) through which the feet hold
    still around its lowest right wrist, the bend and the rise whole (module doc); None when there is
    no such stretch (a foot shifts while the hand is low)."""
    j = gaussian_smooth(np.asarray(joints, np.float64), 1.0)
    if len(j) < 3:
        return None
    feet = np.linalg.norm(np.diff(j[:, FOOT_JOINTS][:, :, [0, 2]], axis=0), axis=-1).max(1) * fps
    low = int(np.argmin(j[:, RIGHT_WRIST, 1]))
    before, after = np.flatnonzero(feet[:low] > STEPPING), np.flatnonzero(feet[low:] > STEPPING)
    start = int(before[-1]) + 1 if len(before) else 0
    end = low + int(after[0]) + 1 if len(after) else len(j)
    wrist = j[:, RIGHT_WRIST, 1]
    half = wrist[low] + 0.5 * (wrist.max() - wrist[low])
    return (start, end) if wrist[start] > half and wrist[end - 1] > half else None


def stand_in_span(asked: str | None, action: str, joints) -> tuple[int, int] | None:
    """(start, end) frames of a take of ``action`` whose (T, J, 3) ``joints`` (on its performer's
    body) play the ``asked`` action it stands in for (``STAND_IN``): a lie-down from its start to
    its sit, a put-down's bend; None when it does not stand in for it (a lie-down that never sits, a
    put-down that steps while its hand is low)."""
    if asked is None or STAND_IN.get(asked) != action:
        return None
    if asked == SIT:
        end = sit_end(joints)
        return None if end is None else (0, end)
    return bend_span(joints)


def played_as(asked: str, rotations, root, contacts, span: tuple[int, int]):
    """(rotations, root, contacts, ``asked``, what it says) of a take's ``span`` (``stand_in_span``)
    made into the action it stands in for: a sit as it is, a pick-up played backwards."""
    start, end = span
    if asked == SIT:
        return rotations[start:end], root[start:end], contacts[start:end], SIT, "its sit on the floor"
    return (np.ascontiguousarray(rotations[start:end][::-1]), np.ascontiguousarray(root[start:end][::-1]),
            np.ascontiguousarray(contacts[start:end][::-1]), asked, "its bend played backwards")
