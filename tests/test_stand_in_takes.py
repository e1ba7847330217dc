"""Takes standing in for an action no take is of: a put-down played backwards for a pick-up, a
lie-down played to its sit for a sit."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.stand_in_takes import STAND_IN, stand_in

pytestmark = pytest.mark.usefixtures("one_thread")


def test_a_put_down_backwards_is_a_pick_up():
    rot = np.arange(5 * 24 * 9, dtype=np.float32).reshape(5, 24, 3, 3)
    root = np.arange(15, dtype=np.float32).reshape(5, 3)
    con = np.array([[1, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0], [0, 1, 0, 1], [1, 1, 1, 1]], np.uint8)
    r, t, c, action, said = stand_in("pick up", "put down", rot, root, con, pose=None)
    assert action == "pick up" and said == "played backwards"
    assert np.array_equal(r, rot[::-1]) and np.array_equal(t, root[::-1]) and np.array_equal(c, con[::-1])
    assert stand_in("pick up", "walk", rot, root, con, None) is None     # only the action that stands in
    assert stand_in("put down", "put down", rot, root, con, None) is None  # a take of the action itself
    assert stand_in(None, "put down", rot, root, con, None) is None
    assert STAND_IN == {"sit": "lie down", "pick up": "put down"}


def test_picking_something_up_plays_a_captured_put_down_backwards():
    """No take picks something up; HDM05's put-downs bend, set something on the floor with the right
    hand and stand up: played backwards the right hand goes down to the floor and comes back up."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    m = gen.generate_batch([Request("a man picks up a box from the floor", seconds=4, seed=0)])[0]
    assert "depositFloorR" in m.provenance and m.provenance.endswith("played backwards"), m.provenance
    wrist = m.joints[:, 21, 1]
    low = int(np.argmin(wrist))
    assert wrist[low] < 0.35 and wrist[0] > 0.8 and wrist[-1] > 0.8 and 0 < low < len(wrist) - 1
    assert m.joints[0, 0, 1] > 0.85 and m.joints[-1, 0, 1] > 0.85          # standing before and after
