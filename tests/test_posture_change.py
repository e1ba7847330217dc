"""A change of posture the words ask for is made (core/generation/posture_change.py): "gets up" rises
from low, "lies down" ends low, whoever the words say does it."""
from __future__ import annotations

import numpy as np

from shapemove.core.generation.posture_change import MIN_CHANGE, posture_change, posture_kept


def _rooted(y) -> np.ndarray:
    f = np.zeros((len(y), 263))
    f[:, 3] = y
    return f


def test_the_root_height_change_is_a_share_of_the_highest_root():
    rise = _rooted(np.r_[np.full(20, 0.2), np.full(20, 0.9)])
    assert abs(posture_change(rise) - 0.7 / 0.9) < 1e-9
    assert abs(posture_change(rise[::-1]) + 0.7 / 0.9) < 1e-9
    assert abs(posture_change(_rooted(np.full(40, 0.9)))) < 1e-9


def test_only_candidates_that_make_the_change_compete_when_one_does():
    stand = _rooted(np.full(40, 0.9))
    rise = _rooted(np.linspace(0.2, 0.9, 40))
    small = _rooted(np.linspace(0.9 * (1 - MIN_CHANGE) + 0.05, 0.9, 40))   # rises less than MIN_CHANGE
    keep = np.ones(3, bool)
    assert posture_kept("get up", [stand, rise, small], keep).tolist() == [False, True, False]
    assert posture_kept("lie down", [stand, rise[::-1], small], keep).tolist() == [False, True, False]
    assert posture_kept("get up", [stand, small], np.ones(2, bool)).tolist() == [True, True]   # none: all
    assert posture_kept("walk", [stand, rise], np.ones(2, bool)).tolist() == [True, True]     # no posture
    assert posture_kept("get up", [stand, rise], np.array([True, False])).tolist() == [True, False]   # set aside


def test_the_default_model_gets_up_and_lies_down_whoever_does_it():
    """"an old man gets up": the TMA preferred a sample of an old man standing (0.74) to the captured
    get-ups (0.24 + 0.3); now the get-up plays, from the floor to standing, on every seed; a lie-down
    ends lying (its take cut to its end, not its busiest stretch)."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    for seed in range(3):
        up = gen.generate_batch([Request("an old man gets up", seed=seed, seconds=3)])[0]
        y = up.joints[:, 0, 1]
        assert up.provenance.startswith("captured:") and y[-5:].mean() - y[:5].mean() > 0.5, (seed, up.provenance)
        down = gen.generate_batch([Request("an exhausted woman lies down on the floor", seed=seed, seconds=3)])[0]
        y = down.joints[:, 0, 1]
        assert y[:5].mean() - y[-5:].mean() > 0.5 and y[-5:].mean() < 0.3, seed


def test_a_lie_down_segment_starts_standing_and_ends_lying():
    """"a man lies down, then gets up": in a 3 s segment the captured lie-down's last 3 s started on
    its knees (the take's first drop is 4-7 s before its end); its 5.3 s segment starts standing,
    lies with the head on the floor, and the get-up ends standing (seeds 0-1)."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    for seed in (0, 1):
        m = gen.generate_batch([Request("a man lies down, then gets up", seed=seed)])[0]
        (s0, e0), (s1, e1) = m.segment_bounds
        root, head = m.joints[:, 0, 1], m.joints[:, 15, 1]
        assert e0 - s0 >= 100, (seed, e0 - s0)                             # 5.2 s (whole codes of 5.3)
        assert root[:5].mean() > 0.8 and head[:5].mean() > 1.4, seed       # standing at the start
        assert head[e0 - 10:e0].mean() < 0.35, seed                         # lying at the seam
        assert root[-5:].mean() > 0.8 and head[-5:].mean() > 1.4, seed      # up again at the end


def _with_head(y, head) -> np.ndarray:
    f = _rooted(y)
    f[:, 47] = head          # joint 15's height in the features (ric: heights are the floor's)
    return f


def test_a_sit_keeps_the_head_up_and_a_lie_down_puts_it_down():
    """Both go down as far (the root 0.9 -> 0.2 m); lying, the head ends 0.15 m high, under LYING
    (0.35) of its highest 1.6 m; sitting it stays at 0.9 m. A sit keeps the one whose head stays up
    (and, with none going down that way, one that does not lie rather than one that does); a
    lie-down the one whose head goes down."""
    from shapemove.core.generation.posture_change import LYING, lies

    down = np.linspace(0.9, 0.2, 40)
    lying = _with_head(down, np.linspace(1.6, 0.15, 40))
    sitting = _with_head(down, np.linspace(1.6, 0.9, 40))
    standing = _with_head(np.full(40, 0.9), np.full(40, 1.6))
    assert lies(lying) and not lies(sitting) and not lies(standing)
    low = lambda h: _with_head(down, np.r_[np.linspace(1.6, h, 10), np.full(30, h)])   # noqa: E731
    assert lies(low(0.5)) and not lies(low(0.6)) and 0.5 < LYING * 1.6 < 0.6   # 0.31 and 0.375 of 1.6 m
    keep = np.ones(3, bool)
    assert posture_kept("sit", [lying, sitting, standing], keep).tolist() == [False, True, False]
    assert posture_kept("lie down", [lying, sitting, standing], keep).tolist() == [True, False, False]
    assert posture_kept("sit", [lying, standing], np.ones(2, bool)).tolist() == [False, True]   # no sit: not lying
    assert posture_kept("sit", [lying, lying], np.ones(2, bool)).tolist() == [True, True]       # all lie: all


def test_a_lie_down_starts_standing_only_when_it_starts_at_its_start(openbody):
    """HDM05's captured lie-downs start standing (root at 1.0-1.1 of the leg's length); their last
    3 s start in a crouch, as the codes' last seconds a 3 s "sits down" was made of. A sit keeps
    the candidates that start standing when any does; a lie-down the ones that end lying, however
    they start."""
    from shapemove.core.generation.generate import Generator
    from shapemove.core.generation.posture_change import HEAD_Y, posture_kept, starts_standing

    pool = Generator(None, body=openbody).pool
    i = pool.ids.index("HDM_bd_lieDownFloor_001_120")
    whole = pool.window(i, len(pool.take(i)["rotations"]), 0).features
    last = pool.window(i, 80, 0).features    # its last 4 s: from kneeling to lying
    assert starts_standing(whole) and not starts_standing(last)
    assert posture_kept("lie down", [last, whole], np.ones(2, bool)).tolist() == [True, True]   # both end lying
    sit = [np.asarray(f).copy() for f in (last, whole)]    # the two, made to keep the head up: sits
    for f in sit:
        f[:, HEAD_Y] = np.maximum(f[:, HEAD_Y], 0.5 * f[:, HEAD_Y].max())
    assert posture_kept("sit", sit, np.ones(2, bool)).tolist() == [False, True]
