"""Counted jumps (core/generation/count_words.py): "jumps twice" keeps the candidates that leave the
floor the number of times nearest two."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.count_words import (DIP, LIFT, MIN_RUN, counter, dip_spans, flight_spans, nearest_count,
                                                   raise_spans, repetitions)
from shapemove.core.plan.vocabulary import COUNTED
from shapemove.core.plan.reader import asked_count


@pytest.mark.parametrize("text, want", [
    ("a man jumps forward twice", 2),
    ("a person jumps three times", 3),
    ("she hops once", 1),
    ("does five jumping jacks", 5),
    ("he takes two big jumps forward", 2),
    ("jumps 3 times in place", 3),
    ("a person does three squats", 3),
    ("a man squats twice", 2),
    ("she jumps a couple of times", 2),
    ("he does a few jumps", 3),
    ("someone jumps up", None),            # no count
    ("a person jumps", None),              # "a" counts nothing here
    ("a man walks twice around", None),    # no jump
    ("a man jumps over two boxes", None),  # two of something else
    ("a woman jumps 100 times", None),     # beyond MAX_COUNT
    ("she kicks twice", 2),
    ("a man does three kicks", 3),
    ("he kicks three times with his left leg", 3),
    ("someone kicks the ball twice", None),  # a ball's kick is not counted
])
def test_the_words_that_count_jumps_and_squats(text, want):
    got = asked_count(text)
    assert (got and got[1]) == want
    if want is not None:
        assert COUNTED[got[0]] == ("dips" if "squat" in text else "raises" if "jacks" in text else
                                   "kicks" if "kick" in text else "flights")


def _features(heights) -> np.ndarray:
    """(T, 263) features whose four foot joints (7, 8, 10, 11) are at ``heights`` (T,)."""
    f = np.zeros((len(heights), 263))
    for j in (7, 8, 10, 11):
        f[:, 4 + (j - 1) * 3 + 1] = heights
    return f


def test_flights_are_runs_of_both_feet_in_the_air():
    h = np.full(60, 0.03)
    h[10:20] = 0.03 + 2 * LIFT             # a jump
    h[30:30 + MIN_RUN - 1] = 0.5        # too short: a glitch, not a flight
    h[40:50] = 0.03 + LIFT / 2             # too low: a shuffle
    assert flight_spans(_features(h)) == [(10, 20)]
    h[40:50] = 0.03 + 1.5 * LIFT
    assert len(flight_spans(_features(h))) == 2


def test_dips_are_runs_of_the_root_well_under_standing():
    f = np.zeros((60, 263))
    f[:, 3] = 0.95
    f[10:20, 3] = 0.95 - 2 * DIP          # a squat
    f[30:34, 3] = 0.95 - DIP / 2           # a bob: not deep enough
    f[40:40 + MIN_RUN - 1, 3] = 0.3        # too short
    assert dip_spans(f) == [(10, 20)]
    f[45:55, 3] = 0.95 - 1.5 * DIP
    assert len(dip_spans(f)) == 2 and counter("squat")(f) == 2


def test_raises_are_runs_of_both_hands_over_the_head():
    """A jumping jack is counted by its hands: both wrists (20, 21) above the head (15)."""
    f = np.zeros((60, 263))
    for j, y in ((15, 1.6), (20, 1.0), (21, 1.0)):
        f[:, 4 + (j - 1) * 3 + 1] = y
    f[10:18, 4 + 19 * 3 + 1] = f[10:18, 4 + 20 * 3 + 1] = 1.8    # both hands up: a jack
    f[30:38, 4 + 19 * 3 + 1] = 1.8                              # one hand: a wave, no jack
    f[45:45 + MIN_RUN - 1, 4 + 19 * 3 + 1] = f[45:45 + MIN_RUN - 1, 4 + 20 * 3 + 1] = 1.8   # too short
    assert raise_spans(f) == [(10, 18)]
    assert repetitions("jumping jacks", f) == [(10, 18)] and counter("jumping jacks")(f) == 1


def test_the_nearest_count_competes():
    among = np.array([True, True, True, False, True])
    assert nearest_count([1, 3, 2, 2, 0], 2, among).tolist() == [False, False, True, False, False]
    assert nearest_count([1, 3, 1, 2, 5], 2, among).tolist() == [True, True, True, False, False]   # none has 2
    assert not nearest_count([1, 2], 2, np.zeros(2, bool)).any()


def test_the_default_model_jumps_and_squats_as_many_times_as_asked():
    """The default model, four seeds each, counted on the planted motion (jumps: runs of 3+ frames
    with no foot contact in which the lowest foot joint clears 8 cm; squats: runs of 3+ frames with
    the pelvis 20 cm under its standing height): "a man jumps forward twice" and "someone does four
    jumps in place" (4 s) 7 of 8 asked counts, before (the TMA alone, long flights grounded) 3 of 8;
    "a man squats twice" (6 s) 3 of 4, before 0 of 4."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.motion.contacts import runs

    gen = Generator(None)

    def jumps(m):
        air = ~m.contacts.astype(bool).any(1)
        y = m.joints[:, [7, 8, 10, 11], 1].min(1)
        return sum(1 for a, b in runs(air) if b - a >= 3 and y[a:b].max() > y.min() + 0.08)

    def squats(m):
        y = m.joints[:, 0, 1]
        return sum(1 for a, b in runs(y < np.percentile(y, 90) - 0.2) if b - a >= 3)

    asks = [("a man jumps forward twice", 4, jumps, 2), ("someone does four jumps in place", 4, jumps, 4),
            ("a man squats twice", 6, squats, 2)]
    got = {p: [count(gen.generate_batch([Request(p, seconds=sec, seed=s)])[0]) for s in range(4)]
           for p, sec, count, _ in asks}
    right = sum(n == want for (p, _, _, want) in asks for n in got[p])
    assert right >= 8, got


def test_kicks_are_one_ankle_high_while_the_other_stands():
    """Each single front kick of the built-in library (HDM05 kickLFront1Reps, DeepMimic's kick)
    counts one, its standing foot rising on its toes as it kicks; no squat, sidestep or jog take
    counts any."""
    from shapemove.core.generation.count_words import kick_spans
    from shapemove.core.generation.generate import Generator

    gen = Generator(None)
    pool = gen.pool
    counted = {}
    for i, a in enumerate(pool.actions):
        single = "1Reps" in pool.ids[i] and a == "kick" or pool.ids[i] == "deepmimic_kick"
        if not single and a not in ("squat", "sidestep", "jog"):
            continue
        t = pool.take(i)
        joints = pool.proc.pose_on(t["rotations"], t["root"], t["betas"], 1.0, t["contacts"])
        n = len(kick_spans(pool.proc.features(joints, t["rotations"], t["contacts"])))
        counted.setdefault("kick" if single else a, []).append(n)
    assert len(counted["kick"]) >= 16 and set(counted["kick"]) == {1}
    assert all(set(v) == {0} for k, v in counted.items() if k != "kick")
