"""How an action is done: the manner the words ask against the captured takes' own, read from their
captions by the prompt's reader (plan/vocabulary.MANNERS, generation/manner_words.py)."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.captured_takes import take_manner
from shapemove.core.generation.manner_words import ANY, MILD_ONLY, done_as, manner_kept, unmet_note
from shapemove.core.plan.words import read_words

pytestmark = pytest.mark.usefixtures("one_thread")


@pytest.mark.parametrize("text, manner", [
    ("a man walks proudly", "proud"), ("a tired woman runs", "tired"), ("an old man walks", "old"),
    ("she walks in a proud manner", "proud"), ("a person bows in a childish way", "childish"),
    ("A person walks forward energetically, with youthful vigour.", "youthful"),   # the first of the order
    ("A person walks forward stiffly, like an old person.", "old"),
    ("A person walks with exaggerated strides.", "exaggerated"), ("a man paces nervously", "timid"),
    ("a girl waves both hands excitedly", "energetic"), ("she cheers enthusiastically", "energetic"),
    ("a confident woman struts", "proud"), ("a man walks, not confident", None), ("she walks unconfidently", "timid"),
    ("a heavy man walks", None), ("a man walks", None), ("a person walks slowly", None),   # a body word, a pace
])
def test_the_manner_the_words_say(text, manner):
    w = read_words(text)
    assert w.manner == manner and not set(w.unused) & {"proudly", "tired", "manner", "way", "childish", "nervously"}


def test_a_take_s_manner_is_what_half_its_captions_say():
    assert take_manner(["A person bows happily.", "A human takes a bow cheerfully.", "A person bows."]) == "happy"
    assert take_manner(["A person walks sadly.", "A person walks.", "A human walks.", "Someone walks."]) is None
    assert take_manner(["A person walks.", "A person walks sadly."]) == "sad"                  # half
    assert take_manner([]) is None and take_manner(["A person waves."]) is None


def test_which_takes_compete():
    plain_and_styled = {None, "happy", "proud"}
    assert manner_kept("proud", plain_and_styled) == "proud"      # asked and offered: those takes
    assert manner_kept("sad", plain_and_styled) is None          # asked, none done so: the plain takes
    assert manner_kept("sad", {"happy", "proud"}) is MILD_ONLY   # ... and no plain take: the mild styles
    assert manner_kept(None, plain_and_styled) is None           # none asked: the plain takes
    assert manner_kept(None, {"happy", "sad"}) is MILD_ONLY      # no plain take: the mild styles
    assert manner_kept(None, {"swagger", "sad"}) is ANY          # ... and none of those: every take
    assert manner_kept(None, {"happy", "sad"}, "sprint") is ANY  # a sprint's mild dashes go at a run's pace
    assert manner_kept(None, set()) is ANY and manner_kept("sad", set()) is ANY
    assert done_as("happy", MILD_ONLY) and done_as("energetic", MILD_ONLY) and not done_as("swagger", MILD_ONLY)
    assert not done_as(None, MILD_ONLY) and done_as("swagger", ANY) and done_as(None, None) and not done_as("sad", None)

    class W:
        def __init__(self, manner):
            self.manner = manner

    assert unmet_note("proud", "sit", [W(None)]) == (
        "not done proudly: no captured take of 'sit' is done so (the words are read as a whole)")
    assert unmet_note("proud", "walk", [W("proud")]) == "" and unmet_note(None, "walk", [W(None)]) == ""


def test_an_action_with_no_plain_take_plays_a_mild_style():
    """The library's waves goodbye and walks backward are all styled (Bandai): "a small child waves
    goodbye" played the street thug's wave ("with a swagger"); with no manner asked, the takes done
    energetically, happily or proudly compete."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.manner_words import MILD

    gen = Generator(None)
    for text in ("a small child waves goodbye", "a man walks backwards"):
        for seed in range(2):
            m = gen.generate_batch([Request(text, seed=seed)])[0]
            if m.provenance.startswith("captured: "):
                assert gen.pool.manner(gen.pool.ids.index(m.provenance.split()[2])) in MILD, m.provenance


def test_generating_plays_the_takes_done_as_asked():
    """The default model: "a man bows" drew the bow "like in a musical" (seed 0) and a plain walk
    CMU's "walk, exaggerated stride"; asked a manner, its take plays, and a manner no take of the
    action has is said."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    for seed in range(3):
        bow = gen.generate_batch([Request("a man bows", seed=seed, seconds=3)])[0]
        assert "dataset-1_bow_normal_001" in bow.provenance, bow.provenance
        walk = gen.generate_batch([Request("a woman walks", seed=seed, seconds=3)])[0]
        i = gen.pool.ids.index(walk.provenance.split()[2]) if walk.provenance.startswith("captured: CMU") else None
        assert "exaggerated" not in walk.provenance and (i is None or gen.pool.manner(i) is None), walk.provenance
    proud = gen.generate_batch([Request("a man walks proudly", seed=0, seconds=3)])[0]
    assert "walk_proud" in proud.provenance and not proud.notes
    happy = gen.generate_batch([Request("a man bows happily", seed=1, seconds=3)])[0]
    assert "bow_happy" in happy.provenance
    sit = gen.generate_batch([Request("a man sits down proudly", seed=0, seconds=3)])[0]
    assert "not done proudly: no captured take of 'sit' is done so" in " ".join(sit.notes)
    for seed in range(2):   # no take of a run is done fearfully: a plain one, not the sad run (every seed before)
        run = gen.generate_batch([Request("a man runs fearfully", seed=seed, seconds=3)])[0]
        i = gen.pool.ids.index(run.provenance.split()[2]) if run.provenance.startswith("captured: ") else None
        assert i is None or gen.pool.manner(i) is None, run.provenance
        assert "not done fearfully" in " ".join(run.notes)
    old = gen.generate_batch([Request("an old man walks", seed=0, seconds=3)])[0]
    quick = gen.generate_batch([Request("an old man walks quickly", seed=0, seconds=3)])[0]
    assert "elderly" in old.provenance and "elderly" not in quick.provenance, quick.provenance
    assert "not done like an old person: the captured takes of 'walk' done so are slower than asked" in quick.notes

    def speed(m):
        j = np.asarray(m.joints)
        return np.linalg.norm(j[-1, 0, [0, 2]] - j[0, 0, [0, 2]]) / (len(j) / 20)

    assert speed(quick) > 1.5 * speed(old)   # 0.75 m/s, quickly or not, before
