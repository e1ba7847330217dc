"""The paraphrase bank: every action has phrasings, sentences are grammatical transforms of them, and
training draws from it only where the clip's labels say what the clip holds."""
import random

from shapemove.core.data.actions import ACTIONS
from shapemove.core.data.captions import base_form, gerund
from shapemove.core.data.paraphrase_bank import (BANK, known_sentences, sentence, sequence_sentence,
                                                 training_caption, _base_vp)


def test_every_action_has_a_bank_entry_of_third_person_verb_phrases():
    assert set(BANK) == set(ACTIONS)
    for name, e in BANK.items():
        assert len(e["vps"]) >= 4, name
        for vp in e["vps"]:
            assert vp.split()[0].endswith("s"), (name, vp)  # "walks ...", the form the transforms expect


def test_verb_forms():
    assert [base_form(v) for v in ("walks", "dashes", "lies", "crosses", "tiptoes", "does", "hurries", "goes")] == \
        ["walk", "dash", "lie", "cross", "tiptoe", "do", "hurry", "go"]
    assert [gerund(v) for v in ("runs", "lies", "dances", "hops", "squats", "tiptoes", "boxes")] == \
        ["running", "lying", "dancing", "hopping", "squatting", "tiptoeing", "boxing"]
    assert _base_vp("gets down and lies flat") == "get down and lie flat"


def test_training_caption_uses_the_bank_only_where_the_labels_allow():
    stored = ["A person walks forward happily."]
    rng = random.Random(0)
    assert {training_caption(stored, {"actions": ["walk"]}, rng, share=0.0) for _ in range(20)} == set(stored)
    single = {training_caption(stored, {"actions": ["cartwheel"]}, rng, share=1.0) for _ in range(60)}
    assert stored[0] not in single and len(single) > 20
    # two simultaneous actions (walk while turning): the stored captions say it better
    both = {training_caption(stored, {"actions": ["walk", "turn"]}, rng, share=1.0) for _ in range(20)}
    assert both == set(stored)
    seq = [training_caption(stored, {"actions": ["jog", "wave"], "sequence": ["jog", "wave"]}, rng, share=1.0)
           for _ in range(30)]
    assert all(any(j in s for j in ("then", "before", "followed by", "after that")) for s in seq)
    # roughly half the examples come from the bank at the default share
    mixed = [training_caption(stored, {"actions": ["walk"]}, random.Random(i)) for i in range(400)]
    assert 0.4 < sum(s != stored[0] for s in mixed) / 400 < 0.6


def test_sentences_are_varied_capitalised_and_deterministic():
    s = [sentence("punch", random.Random(i)) for i in range(200)]
    assert len(set(s)) > 80
    assert all(x[0].isupper() and x.endswith(".") for x in s)
    assert known_sentences("punch") == known_sentences("punch") and len(known_sentences("punch")) == 40
    seq = sequence_sentence(["walk", "sit"], random.Random(3))
    assert seq[0].isupper() and seq.endswith(".")


def test_action_balanced_clip_sampling():
    """action_balance 1 draws each main action equally often, 0 each clip."""
    import numpy as np

    from shapemove.core.train.action_balance import clip_weights

    ids = [f"w{i}" for i in range(90)] + ["c0", "c1"] + [f"r{i}" for i in range(8)]
    labels = {c: {"actions": [{"w": "walk", "c": "cartwheel", "r": "run"}[c[0]]]} for c in ids}
    for balance, expect in ((1.0, [1 / 3, 1 / 3, 1 / 3]), (0.0, [0.90, 0.02, 0.08])):
        w = clip_weights(ids, labels, balance)
        share = [w[:90].sum() / w.sum(), w[90:92].sum() / w.sum(), w[92:].sum() / w.sum()]
        assert np.allclose(share, expect), (balance, share)
