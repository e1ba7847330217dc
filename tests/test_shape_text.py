"""Shape texts (core/data/shape_text.py): the size-word table, numeric forms and their parser."""
import itertools

import numpy as np
import pytest

from shapemove.core.data import shape_text as st

BASE = {"height_cm": 182.4, "chest_cm": 101.2, "waist_cm": 99.6, "hip_cm": 104.0, "arm_length_cm": 61.0,
        "leg_length_cm": 86.3}
GRID = [dict(BASE, height_cm=float(h), waist_cm=float(r * h))
        for h, r in itertools.product(np.arange(140, 206, 1.5), np.arange(0.30, 0.70, 0.0075))]


def test_adjective_table_ranges():
    # the written-down ranges (height cm; waist-to-height ratio)
    assert st.ADJECTIVES["tall"] == ((180.0, 190.0), None)
    assert st.ADJECTIVES["short"] == ((155.0, 165.0), None)
    assert st.ADJECTIVES["slim"] == (None, (st.R_MIN, 0.43))
    assert st.ADJECTIVES["heavy-set"] == (None, (0.53, 0.60))
    assert st.ADJECTIVES["lanky"] == ((180.0, st.H_MAX), (st.R_MIN, 0.43))
    assert st.ADJECTIVES["stocky"] == ((st.H_MIN, 180.0), (0.53, st.R_MAX))
    assert st.in_range("tall", 185, 80) and not st.in_range("tall", 179.9, 80) and not st.in_range("tall", 190, 80)
    assert st.in_range("petite", 158, 64) and not st.in_range("petite", 158, 70)     # WHtR 0.405 vs 0.443
    assert st.in_range("big", 185, 100) and not st.in_range("big", 175, 100)


def test_height_and_build_bands_partition_the_bodies():
    for m in GRID:
        h, w = m["height_cm"], m["waist_cm"]
        assert sum(st.in_range(x, h, w) for x in st.HEIGHT_WORDS) == 1
        assert sum(st.in_range(x, h, w) for x in st.BUILD_WORDS) == 1


def test_generated_words_always_lie_in_their_ranges_and_all_are_used():
    used = set()
    for i, m in enumerate(GRID):
        h, w = m["height_cm"], m["waist_cm"]
        for words in st.size_words(m):
            for word in words:
                assert st.in_range(word, h, w), (word, h, w)
                used.add(word)
        text = st.shape_adjectives(m)
        for word in st.ADJECTIVES:
            if f" {word} " in f" {text.replace(',', '')} " and not any(
                    word != o and word in o and f" {o} " in f" {text.replace(',', '')} " for o in st.ADJECTIVES):
                assert st.in_range(word, h, w), (text, h, w)
    assert used == set(st.ADJECTIVES)


def test_word_targets_are_inside_the_ranges():
    for word in st.ADJECTIVES:
        t = st.word_targets(word, height_cm=172.0)
        h = t.get("height_cm", 172.0)
        w = t.get("waist_cm", 0.48 * h)
        assert st.in_range(word, h, w), (word, t)
    assert st.word_targets("tall") == {"height_cm": 185.0}
    assert st.word_targets("slim", 170.0) == {"waist_cm": pytest.approx(0.38 * 170.0)}


@pytest.mark.parametrize("key", [f"clip{i}" for i in range(24)])
def test_numeric_texts_round_trip(key):
    rng = np.random.default_rng(abs(hash(key)) % 2**32)
    m = dict(BASE, height_cm=float(rng.uniform(145, 200)), waist_cm=float(rng.uniform(55, 115)))
    text = st.numeric_shape_text(m, key)
    got = st.parse_shape_text(text)
    imperial = "ft" in text or "'" in text
    assert got["height_cm"] == pytest.approx(m["height_cm"], abs=1.3 if imperial else 0.51), text
    assert got["waist_cm"] == pytest.approx(m["waist_cm"], abs=1.3 if "inch" in text else 0.51), text
    mixed = st.mix_into_prompt("A person jogs forward.", m, key, numeric=True)
    assert mixed.endswith(", jogs forward.")
    got = st.parse_shape_text(mixed)
    assert got["height_cm"] == pytest.approx(m["height_cm"], abs=1.3) and got["waist_cm"] == pytest.approx(m["waist_cm"], abs=1.3)


def test_parser_forms_and_non_shape_text():
    p = st.parse_shape_text
    assert p("1.9 m tall, waist 100 cm") == {"height_cm": pytest.approx(190.0), "waist_cm": 100.0}
    assert p("5'11\" tall with a 34-inch waist") == {"height_cm": pytest.approx(180.34), "waist_cm": pytest.approx(86.36)}
    assert p("someone who stands 6 feet 2 inches tall") == {"height_cm": pytest.approx(187.96)}
    assert p("height: 171 cm") == {"height_cm": 171.0}
    assert p(st.shape_sentence(BASE)) == {"height_cm": 182, "chest_cm": 101, "waist_cm": 100, "hip_cm": 104,
                                          "arm_length_cm": 61, "leg_length_cm": 86}
    for motion in ("a person walks 5 m forward", "jumps 30 centimeters forward", "a tall, heavy-set man",
                   "turns 180 degrees", "a person walks in a figure 8"):
        assert p(motion) == {}, motion


def test_mixed_prompts_and_builder_texts():
    m = dict(BASE, height_cm=186.0, waist_cm=104.0)                 # tall, heavy-set (WHtR 0.56)
    outs = {st.mix_into_prompt("A person jogs.", m, f"k{i}") for i in range(30)}
    assert all(o.endswith(" jogs.") for o in outs) and len(outs) > 5
    assert any(o.startswith(("A tall, heavy-set ", "A tall heavy-set ", "A big ")) for o in outs)
    assert all(not any(w in o for w in ("slim", "short", "petite")) for o in outs)
    assert st.mix_into_prompt("Person taking a hand shower", m, "k") is None
    texts = st.shape_texts(m, "dataset-1_walk_happy_001")
    assert texts[0] == st.shape_sentence(m) and texts[1] == "a tall, heavy-set person"
    assert len(texts) == len(set(texts)) >= 4 and texts == st.shape_texts(m, "dataset-1_walk_happy_001")
    assert any(st.parse_shape_text(t).get("waist_cm") for t in texts[2:])   # a short numeric form
