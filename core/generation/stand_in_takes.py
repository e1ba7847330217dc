"""Actions no captured take is of, played from the takes of another: a sit from a lie-down, played
to where it sits on the floor (``floor_sit.py``); a pick-up from a put-down played backwards.

The archives hold no capture of sitting down nor of picking something up, and the T5 writes
neither reliably. HDM05's 20 ``depositFloorR`` takes bend down, set something on the floor with the
right hand and stand up again; played backwards they bend down, take it from the floor and stand
up: a pick-up, every contact of the feet where it was (time reversed, a planted foot stays
planted). So when the words ask one of these actions and no take is of it, the takes of
``STAND_IN`` compete for it, made into it by ``stand_in``, each saying how ("captured: HDM05 bd
depositFloorR 004 (CC BY-SA 3.0), played backwards").

    rot, root, con, action, said = stand_in("pick up", "put down", rot, root, con, pose)
"""
from __future__ import annotations

import numpy as np

from .floor_sit import SIT, SIT_FROM, sit_end

PICK_UP, PUT_DOWN = "pick up", "put down"
STAND_IN = {SIT: SIT_FROM, PICK_UP: PUT_DOWN}   # an action no take is of: the action whose takes play it


def stand_in(asked: str | None, action: str, rotations, root, contacts, pose):
    """(rotations, root, contacts, action, what it says) of a take of ``action`` made into the
    ``asked`` action it stands in for (``STAND_IN``), or None when it does not stand in for it (or,
    a lie-down, never sits); ``pose(rot, root, con) -> (T, J, 3)`` joints on the performer's body."""
    if asked is None or STAND_IN.get(asked) != action:
        return None
    if asked == SIT:
        end = sit_end(pose(rotations, root, contacts))
        if end is None:
            return None
        return rotations[:end], root[:end], contacts[:end], SIT, "its sit on the floor"
    return (np.ascontiguousarray(rotations[::-1]), np.ascontiguousarray(root[::-1]),
            np.ascontiguousarray(contacts[::-1]), asked, "played backwards")
