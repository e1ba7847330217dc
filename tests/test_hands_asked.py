"""A gesture of the hands is made with the hands the words say: one or both (generation/hands_asked.py)."""
from __future__ import annotations

import pytest

from shapemove.core.generation.hands_asked import hands_wanted
from shapemove.core.plan.words import read_words

pytestmark = pytest.mark.usefixtures("one_thread")


@pytest.mark.parametrize("prompt, asked, wanted", [
    ("a man waves", "wave", None),          # neither said: every take competes
    ("she waves at her friend", "wave", None),
    ("a man waves with both hands", "wave", True),
    ("she raises her hands", "raise hand", True),
    ("a man waves his arms over his head", "wave", True),
    ("someone raises a hand", "raise hand", False),
    ("running flat out, she lifts one hand high", "raise hand", False),
    ("he waves with his left hand", "wave", False),
    ("a woman bows", "bow", None),          # no gesture of the hands
    ("a man walks", "walk", None),
])
def test_the_hands_the_words_ask(prompt, asked, wanted):
    assert hands_wanted(read_words(prompt), asked) is wanted


def test_a_named_foot_says_nothing_of_the_hands():
    """"kicks with her right leg" named one hand ("side: right foot; one hand" in what was understood)."""
    from shapemove.core.plan.reading import said

    assert read_words("a woman kicks with her right leg").hands is None
    assert said(read_words("a woman kicks with her right leg").understood()) == "kick; side: right foot"
    assert read_words("he waves with his left hand").hands == "one"
    assert read_words("first wave with the right hand").hands == "one"


def test_the_library_tells_waves_of_one_hand_from_waves_of_both(openbody):
    """Bandai's wave-both-hands takes are made with both hands, its wave-right-hand ones with one;
    the both-hands takes are the nearest by caption to a wave asked with one hand too, which gets one
    now (seeds 0-2), and "with both hands" both."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.hands_asked import made_with_both

    gen = Generator(None, body=openbody)
    pool = gen.pool
    assert pool.two_handed(pool.ids.index("dataset-2_wave-both-hands_normal_011"))
    assert not pool.two_handed(pool.ids.index("dataset-2_wave-right-hand_normal_021"))
    for seed in range(3):
        one = gen.generate_batch([Request("a man waves a hand", seed=seed, seconds=3)])[0]
        both = gen.generate_batch([Request("a man waves with both hands", seed=seed, seconds=3)])[0]
        assert "both-hands" not in one.provenance and not made_with_both(one.joints), one.provenance
        assert "both-hands" in both.provenance and made_with_both(both.joints), both.provenance


def test_the_plain_takes_made_with_both_hands_are_reached_past_styled_ones(openbody):
    """"she throws both hands up": the nearest two-handed raised hands by caption are Bandai's styled
    ones (energetic, elderly, ...), which a prompt with no manner does not let compete; the plain
    ones after them are offered (none were: the places went to takes of other actions)."""
    from shapemove.core.generation.generate import Generator

    gen = Generator(None, body=openbody)
    pool = gen.pool
    text = gen._embed_texts(["she throws both hands up"])[0]
    for seed in range(3):
        got = pool.nearest(text, "raise hand", seed, hands=True, competes=lambda i: pool.manner(i) is None)
        raised = [i for i in got if pool.actions[i] == "raise hand"]
        assert len(raised) >= 3, [pool.ids[i] for i in got]
        assert all(pool.two_handed(i) and pool.manner(i) is None for i in raised)


def test_both_arms_asked_of_any_action_keeps_the_candidates_made_with_both():
    """"someone stretches both arms above the head" (seed 0) chose a sample raising the left arm
    alone (wrists at 1.46 and 0.85 m, the head at 1.46); now both go above the head. Words that say
    no hands keep every candidate."""
    import numpy as np

    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.hands_asked import both_kept, made_with_both

    gen = Generator(None)
    m = gen.generate_batch([Request("someone stretches both arms above the head", "a short, slim woman", seed=0)])[0]
    head = m.joints[:, 15, 1].max()
    assert made_with_both(m.joints) and min(m.joints[:, 20, 1].max(), m.joints[:, 21, 1].max()) > head
    keep = np.array([True, False, True])
    assert both_kept(read_words("a man waves"), [None] * 3, keep) is keep        # nothing said: untouched
    assert both_kept(None, [None] * 3, keep) is keep
