"""Takes standing in for an action no take is of: a put-down played backwards for a pick-up, a
lie-down played to its sit for a sit."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.stand_in_takes import STAND_IN, bend_span, played_as, stand_in_span

pytestmark = pytest.mark.usefixtures("one_thread")


def put_down_joints(foot_moves_low: bool = False) -> np.ndarray:
    """A put-down's joints at 20 fps: steps in (frames 0-9, the feet at 1 m/s), the right wrist down
    to 0.2 m and back to 1.0 m over frames 12-28 with the feet still, steps away (frames 31-39);
    ``foot_moves_low``: a foot shuffles while the hand is at the floor."""
    T = 40
    j = np.zeros((T, 24, 3))
    x = np.concatenate([np.arange(10) * 0.05, np.full(21, 0.45), 0.45 + np.arange(1, 10) * 0.05])
    j[:, [7, 8, 10, 11], 0] = x[:, None]
    if foot_moves_low:
        j[19:22, 10, 2] = [0.0, 0.1, 0.2]
    wrist = np.ones(T)
    wrist[12:29] = 0.6 + 0.4 * np.cos(np.linspace(0, 2 * np.pi, 17))
    j[:, 21, 1] = wrist
    return j


def test_a_put_down_backwards_is_a_pick_up():
    """Its bend alone, where the feet hold still through it; a take that steps while its hand is low
    does not stand in."""
    rot = np.arange(40 * 24 * 9, dtype=np.float32).reshape(40, 24, 3, 3)
    root = np.arange(120, dtype=np.float32).reshape(40, 3)
    con = np.tile(np.array([[1, 1, 0, 0], [0, 0, 1, 1]], np.uint8), (20, 1))
    start, end = bend_span(put_down_joints())
    assert 9 <= start <= 12 and 29 <= end <= 32                  # from standing, down, up, to standing
    assert stand_in_span("pick up", "put down", put_down_joints()) == (start, end)
    r, t, c, action, said = played_as("pick up", rot, root, con, (start, end))
    assert action == "pick up" and said == "its bend played backwards"
    assert np.array_equal(r, rot[start:end][::-1]) and np.array_equal(t, root[start:end][::-1])
    assert np.array_equal(c, con[start:end][::-1])
    assert bend_span(put_down_joints(foot_moves_low=True)) is None   # a step while the hand is low
    assert stand_in_span("pick up", "put down", put_down_joints(True)) is None   # no stand-in
    assert stand_in_span("pick up", "walk", put_down_joints()) is None     # only the action that stands in
    assert stand_in_span("put down", "put down", put_down_joints()) is None  # a take of the action itself
    assert stand_in_span(None, "put down", put_down_joints()) is None
    r, t, c, action, said = played_as("sit", rot, root, con, (0, 25))   # a sit: as it is, to where it sits
    assert action == "sit" and said == "its sit on the floor" and np.array_equal(r, rot[:25]) and np.array_equal(c, con[:25])
    assert STAND_IN == {"sit": "lie down", "pick up": "put down"}


def test_picking_something_up_plays_a_captured_put_down_backwards():
    """No take picks something up; HDM05's put-downs bend, set something on the floor with the right
    hand and stand up: played backwards the right hand goes down to the floor and comes back up, the
    body where it stood."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    m = gen.generate_batch([Request("a man picks up a box from the floor", seconds=4, seed=0)])[0]
    assert "depositFloorR" in m.provenance and m.provenance.endswith("played backwards"), m.provenance
    wrist = m.joints[:, 21, 1]
    low = int(np.argmin(wrist))
    assert wrist[low] < 0.35 and wrist[0] > 0.8 and wrist[-1] > 0.8 and 0 < low < len(wrist) - 1
    assert m.joints[0, 0, 1] > 0.85 and m.joints[-1, 0, 1] > 0.85          # standing before and after
    travel = np.linalg.norm(m.joints[:, 0, [0, 2]] - m.joints[0, 0, [0, 2]], axis=1).max()
    assert travel < 0.4, travel            # no steps back: the put-down's walk up and away left out
