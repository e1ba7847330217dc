"""A take of an action done over and over that stops half way competes only when every take
offered does (generation/held_repetition.py)."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.captured_takes import Window
from shapemove.core.generation.held_repetition import MOST_HELD, performed


def _window(frames: int, held: int, action: str = "arm circles", cid: str = "t") -> Window:
    z = np.zeros
    return Window(z((frames, 24, 3, 3), np.float32), z((frames, 3), np.float32), z((frames, 4), np.uint8),
                  z((24, 3), np.float32), z((frames - 1, 263), np.float32), action, cid, "captured: test", held=held)


def test_a_repetition_held_most_of_the_time_gives_way_to_one_that_goes_on():
    held = _window(80, 43, cid="circles twice, then stands")       # 1.9 s of circles, 2.1 s held
    looped = _window(80, 0, cid="one circle, looped")
    barely = _window(80, int(MOST_HELD * 80), cid="held a quarter")
    assert [w.clip_id for w in performed([held, looped, barely], "arm circles")] == \
        ["one circle, looped", "held a quarter"]


@pytest.mark.parametrize("asked, times", [("kick", None), ("arm circles", 3), (None, None)])
def test_held_takes_compete_for_a_single_action_or_a_count(asked, times):
    held, looped = _window(80, 43), _window(80, 0)
    assert performed([held, looped], asked, times) == [held, looped]   # a kick held after it; "three arm circles"


def test_when_every_take_stops_they_all_compete():
    a, b = _window(80, 43), _window(80, 60)
    assert performed([a, b], "jumping jacks") == [a, b]


def test_arm_circles_go_on_to_the_end_on_the_spot(openbody):
    """With the default model: "an athlete does arm circles" for 4 s plays a captured arm circle
    looped, not two circles held still for their last 2.1 s; the arms still go round in the last two
    seconds, and the sway of a circle does not add up to a walk (``take_loop.looped_repetition``)."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None, body=openbody)
    m = gen.generate_batch([Request("an athlete does arm circles", seconds=4, seed=4)])[0]
    assert "rotateArmsBoth" in m.provenance and not any("held" in n for n in m.notes)
    wrists = m.joints[40:, [20, 21], 1]                              # the last 2 s
    assert np.ptp(wrists, axis=0).min() > 0.3                        # both arms still circling
    root = m.joints[:, 0]
    assert np.linalg.norm(root[-1, [0, 2]] - root[0, [0, 2]]) < 0.2   # on the spot


def _flights(joints) -> int:
    low = np.asarray(joints)[:, [7, 8, 10, 11], 1].min(1)
    up = (low > 0.08).astype(int)
    return int((np.diff(up) == 1).sum())


def test_hops_go_on_hopping_along_or_on_the_spot(openbody):
    """With the default model: HDM05's hops on both feet are single hops (0.7-0.8 s, a metre forward
    each). "a girl skips along happily" played one and stood for 3.3 s; a hop is now done over and
    over (``actions.REPEATED``) and goes on as it repeats (``MOVES_ON``): it hops along. On the spot,
    the repeated hops are brought back to 0.5 m (``on_the_spot.py``)."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None, body=openbody)
    m = gen.generate_batch([Request("a girl skips along happily", seed=0)])[0]
    root = m.joints[:, 0, [0, 2]]
    assert "hopBothLegs" in m.provenance and _flights(m.joints) >= 4
    assert np.linalg.norm(root[-1] - root[0]) > 2.0                              # along
    m = gen.generate_batch([Request("a person hops on the spot", seed=0)])[0]
    assert _flights(m.joints) >= 4 and np.ptp(m.joints[:, 0, [0, 2]], axis=0).max() < 0.7



def test_a_hop_loops_only_when_the_words_ask_for_a_hop(openbody):
    """A take of an action that goes on as it repeats (``actions.MOVES_ON``) loops only for its own
    action: drawn by caption for other words ("a child toddles forward" in ``eval paraphrase``,
    seed 1), six looped hops were chosen over the walks; not asked for, it is held."""
    from shapemove.core.generation.generate import Generator

    pool = Generator(None, body=openbody).pool
    i = pool.ids.index("HDM_bd_hopBothLegs1hops_002_120")
    asked = pool.window(i, 80, 0, asked="hop")
    other = pool.window(i, 80, 0, asked=None)
    assert asked.looped > 40 and asked.held < 10
    assert other.looped == 0 and other.held > 40
