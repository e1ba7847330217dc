"""A pick-up or a put-down reaches the floor (core/generation/floor_reach.py)."""
from __future__ import annotations

import numpy as np

from shapemove.core.generation.floor_reach import HEAD_Y, LOW_HAND, WRISTS_Y, floor_reached, reaches_floor


def candidate(lowest_wrist: float, head: float = 1.6) -> np.ndarray:
    """(40, 263) features whose wrists go from 0.9 m down to ``lowest_wrist`` and back, the head at
    ``head`` m."""
    f = np.zeros((40, 263), np.float32)
    f[:, WRISTS_Y] = 0.9
    f[15:25, WRISTS_Y[1]] = lowest_wrist
    f[:, HEAD_Y] = head
    return f


def test_only_the_candidates_whose_hand_reaches_the_floor_compete():
    standing, picking, crouched = candidate(0.85), candidate(0.2), candidate(0.38)
    assert not reaches_floor(standing) and reaches_floor(picking)
    assert reaches_floor(crouched) == (0.38 < LOW_HAND * 1.6)            # 0.4 m on a 1.6 m head: just not
    assert not reaches_floor(candidate(0.2, head=0.7))                   # a body lying low: 0.2 is not under 0.175
    keep = np.ones(3, bool)
    assert floor_reached("pick up", [standing, picking, standing], keep).tolist() == [False, True, False]
    assert floor_reached("put down", [standing, picking], np.array([True, False])).tolist() == [True, False]  # none kept reaches
    assert floor_reached("pick up", [standing, standing], np.ones(2, bool)).tolist() == [True, True]   # none does: all
    assert floor_reached("wave", [standing, picking], np.ones(2, bool)).tolist() == [True, True]
    assert floor_reached(None, [standing], np.ones(1, bool)).tolist() == [True]


def test_an_old_woman_picks_a_box_up_from_the_floor():
    """The TMA chose a sample of an old woman standing about, wrists never under 0.85 m, over the
    captured put-downs played backwards: now her right hand goes down to the floor and back up."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    m = gen.generate_batch([Request("an old woman picks up a box", seconds=4, seed=0)])[0]
    wrist = m.joints[:, 21, 1]
    assert wrist.min() < 0.3 and wrist[0] > 0.7 and wrist[-1] > 0.5, (m.provenance, wrist.min())   # up again, holding it
