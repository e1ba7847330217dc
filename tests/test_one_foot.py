"""Hopping on one foot: every capture lands on both feet, and the motion says so (generation/one_foot.py)."""
from __future__ import annotations

import pytest

from shapemove.core.generation.one_foot import one_foot_note
from shapemove.core.plan.words import read_words

pytestmark = pytest.mark.usefixtures("one_thread")


def test_one_foot_is_read_of_a_hop_or_jump_and_said():
    note = "no capture hops on one foot: every take and sample lands on both feet"
    for text in ("a child hops on one foot", "she hops on her left leg", "a one-legged hop",
                 "hopping using only one foot", "he hops on a single leg"):
        w = read_words(text)
        assert w.one_foot and w.understood()["one_foot"] is True, text
        assert one_foot_note(w, "hop") == note, text
    assert one_foot_note(read_words("a man jumps on one foot"), "jump") == \
        "no capture jumps on one foot: every take and sample lands on both feet"
    for text in ("a child hops on both feet", "a child hops", "she balances on one leg", "he kicks with one leg",
                 "a man stands on his left foot"):
        assert not read_words(text).one_foot, text                       # a balance or a kick is on one leg
    assert read_words("hop on one leg").unused == ()                     # the words are taken: not "leg" unused
    assert one_foot_note(read_words("a child hops"), "hop") == ""
    assert one_foot_note(read_words("a child hops on one foot"), None) == ""


def test_the_motion_of_a_hop_on_one_foot_says_it_lands_on_both():
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    one = gen.generate_batch([Request("a child hops on one foot", seed=0, seconds=3)])[0]
    assert "no capture hops on one foot" in " ".join(one.notes), one.notes
    both = gen.generate_batch([Request("a child hops along", seed=0, seconds=3)])[0]
    assert not any("one foot" in n for n in both.notes), both.notes
    waving = gen.generate_batch([Request("a child hops on one foot while waving", seed=0, seconds=3)])[0]
    assert waving.part_prompts and "no capture hops on one foot" in " ".join(waving.notes), waving.notes
