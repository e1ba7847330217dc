"""A pose the words keep: the raise at its top, a squat at its lowest (core/generation/held_pose.py)."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.held_pose import held_from, held_from_peak, lowest_frame, peak_frame
from shapemove.core.generation.track import Track
from shapemove.core.plan.reading import said
from shapemove.core.plan.words import read_words


@pytest.mark.parametrize("text, held", [
    ("a teenager runs across the field with both arms raised", True),
    ("a woman stands, hands raised", True),
    ("he jogs holding his arms above his head", True),
    ("Circling the room on foot, he keeps his hand raised.", True),
    ("a man raises his hand", False),
    ("she raises both arms, then lowers them", False),
    ("a girl waves her right hand above her head", False),
])
def test_the_words_of_a_held_raise(text, held):
    w = read_words(text)
    assert w.arms_held is held
    assert "raise hand" in w.actions or not held          # the state is a raise of the hands
    assert ("arms_held" in w.understood()) is held
    assert ("arms held raised" in said(w.understood())) is held   # the line the CLI prints
    if held:   # every word of the state is taken
        assert not {"raised", "arms", "hands", "hand", "head", "above", "holding", "keeps"} & set(w.unused)


def _track(heights) -> Track:
    """A standing track whose right wrist rises and falls through ``heights`` (m above the pelvis)."""
    T = len(heights)
    joints = np.zeros((T, 22, 3))
    joints[:, 0, 1] = 1.0
    joints[:, 15, 1] = 1.6
    joints[:, 20, 1] = 1.1
    joints[:, 21, 1] = 1.0 + np.asarray(heights)
    contacts = np.zeros((T, 4), np.uint8)
    contacts[:4] = 1
    return Track(joints, contacts)


def test_the_track_is_held_at_the_top_of_its_raise():
    heights = [0.1, 0.3, 0.6, 0.8, 0.7, 0.4, 0.2, 0.1]
    t = _track(heights)
    assert peak_frame(t.joints) == 3
    h = held_from_peak(t)
    assert len(h) == len(t)
    np.testing.assert_array_equal(h.joints[:4], t.joints[:4])
    assert np.allclose(h.joints[4:, 21, 1], 1.8) and np.allclose(h.joints[4:], t.joints[3])
    np.testing.assert_array_equal(h.contacts[4:], np.repeat(t.contacts[3:4], 4, 0))
    top = _track([0.1, 0.2, 0.3, 0.4])          # still rising at its end: nothing to hold
    assert held_from_peak(top) is top


def _above_head(m) -> np.ndarray:
    j = np.asarray(m.joints)
    return j[:, [20, 21], 1].max(1) - j[:, 15, 1]


def test_the_default_model_keeps_the_arms_raised():
    from shapemove.core.generation.generate import Request
    from shapemove.core.generation.loaded_generator import loaded_generator

    gen = loaded_generator(None)
    stand, run, raise_ = gen.generate_batch([
        Request("a woman stands with her arms raised", seconds=4.0, seed=0),
        Request("a teenager runs across the field with both arms raised", seconds=4.0, seed=0),
        Request("a man walks and raises both arms", seconds=4.0, seed=0)])
    last = slice(-20, None)   # the last second
    assert _above_head(stand)[last].min() > 0.05 and any("held from" in n for n in stand.notes)
    assert _above_head(run)[last].min() > 0.05 and any("held from" in n for n in run.notes)
    assert np.linalg.norm(run.transl[-1, [0, 2]] - run.transl[0, [0, 2]]) > 4.0     # the legs still run
    assert _above_head(raise_)[last].max() < 0.0 and not any("held from" in n for n in raise_.notes)

    # both parts generated from codes: the hold is an edit, so no tokens are kept to decode it away again
    gen.set_captured(False)
    try:
        coded = gen.generate_batch([Request("a man walks with both arms raised", seconds=4.0, seed=0)])[0]
    finally:
        gen.set_captured(True)
    assert coded.provenance.startswith("generated") or "legs: generated" in coded.provenance
    assert any("held from" in n for n in coded.notes) and _above_head(coded)[last].min() > 0.0
    assert (coded.tokens is None or len(coded.tokens) == 0) and coded.arms_tokens is None


@pytest.mark.parametrize("text, held", [
    ("a man does a deep squat and holds it", True), ("a woman squats down and stays there", True),
    ("she crouches and holds the position", True), ("he squats and remains in that position", True),
    ("a man squats", False), ("she walks and stays there", False),   # no squat to keep down
    ("he squats, then stands up", False),
])
def test_the_words_of_a_held_squat(text, held):
    w = read_words(text)
    assert w.held_low is held and ("held at its lowest" in said(w.understood())) is held
    if held:
        assert not {"holds", "stays", "remains", "position", "there", "it"} & set(w.unused)


def test_the_track_is_held_at_its_lowest():
    """Hand-derived: a pelvis going 1.0 -> 0.5 -> 1.0 m is lowest at frame 3; held from there, the
    rest of the track is that frame's pose."""
    t = _track([0.1] * 7)
    t.joints[:, 0, 1] = [1.0, 0.8, 0.6, 0.5, 0.6, 0.8, 1.0]
    assert lowest_frame(t.joints) == 3
    h = held_from(t, lowest_frame(t.joints))
    assert len(h) == len(t) and np.allclose(h.joints[3:], t.joints[3]) and np.allclose(h.joints[:4], t.joints[:4])


def test_generation_keeps_a_squat_down_when_the_words_hold_it():
    """"a man does a deep squat and holds it" went down and stood up again in 1.8 s, then stood; now
    the pelvis stays at its lowest to the end (no note that the take's last pose is held)."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    held = gen.generate_batch([Request("a man does a deep squat and holds it", seed=0, seconds=4)])[0]
    plain = gen.generate_batch([Request("a man does a squat", seed=0, seconds=4)])[0]
    pelvis, stand = held.joints[:, 0, 1], plain.joints[-1, 0, 1]
    assert pelvis[-1] == pytest.approx(pelvis.min(), abs=0.02) and pelvis[-1] < plain.joints[0, 0, 1] - 0.3
    assert stand > plain.joints[:, 0, 1].min() + 0.3                      # the plain squat stands up again
    assert any("held at its lowest" in n for n in held.notes) and not any("last pose is held" in n for n in held.notes)
    assert held.joints[:, :, 1].min() > -0.05
