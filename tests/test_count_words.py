"""Counted jumps (core/generation/count_words.py): "jumps twice" keeps the candidates that leave the
floor the number of times nearest two."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.count_words import LIFT, MIN_FLIGHT, asked_jumps, flights, nearest_count


@pytest.mark.parametrize("text, want", [
    ("a man jumps forward twice", 2),
    ("a person jumps three times", 3),
    ("she hops once", 1),
    ("does five jumping jacks", 5),
    ("he takes two big jumps forward", 2),
    ("jumps 3 times in place", 3),
    ("someone jumps up", None),            # no count
    ("a man walks twice around", None),    # no jump
    ("a man jumps over two boxes", None),  # two of something else
    ("a woman jumps 100 times", None),     # beyond MAX_COUNT
])
def test_the_words_that_count_jumps(text, want):
    assert asked_jumps(text) == want


def _features(heights) -> np.ndarray:
    """(T, 263) features whose four foot joints (7, 8, 10, 11) are at ``heights`` (T,)."""
    f = np.zeros((len(heights), 263))
    for j in (7, 8, 10, 11):
        f[:, 4 + (j - 1) * 3 + 1] = heights
    return f


def test_flights_are_runs_of_both_feet_in_the_air():
    h = np.full(60, 0.03)
    h[10:20] = 0.03 + 2 * LIFT             # a jump
    h[30:30 + MIN_FLIGHT - 1] = 0.5        # too short: a glitch, not a flight
    h[40:50] = 0.03 + LIFT / 2             # too low: a shuffle
    assert flights(_features(h)) == 1
    h[40:50] = 0.03 + 1.5 * LIFT
    assert flights(_features(h)) == 2


def test_the_nearest_count_competes():
    among = np.array([True, True, True, False, True])
    assert nearest_count([1, 3, 2, 2, 0], 2, among).tolist() == [False, False, True, False, False]
    assert nearest_count([1, 3, 1, 2, 5], 2, among).tolist() == [True, True, True, False, False]   # none has 2
    assert not nearest_count([1, 2], 2, np.zeros(2, bool)).any()


def test_the_default_model_jumps_as_many_times_as_asked():
    """The default model, "a man jumps forward twice" and "someone does four jumps in place", four
    seeds each, counted on the planted motion (runs of 3+ frames with no foot contact in which the
    lowest foot joint clears 8 cm): 7 of 8 asked counts; before (the TMA alone, long flights
    grounded) 3 of 8."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.motion.contacts import runs

    gen = Generator(None)

    def jumps(m):
        air = ~m.contacts.astype(bool).any(1)
        y = m.joints[:, [7, 8, 10, 11], 1].min(1)
        return sum(1 for a, b in runs(air) if b - a >= 3 and y[a:b].max() > y.min() + 0.08)

    got = {p: [jumps(gen.generate_batch([Request(p, seconds=4, seed=s)])[0]) for s in range(4)]
           for p in ("a man jumps forward twice", "someone does four jumps in place")}
    right = sum(n == want for (p, ns), want in zip(got.items(), (2, 4)) for n in ns)
    assert right >= 6, got
