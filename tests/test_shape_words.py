"""core/text/shape_words.py: the one reader of shape words and numbers (issue #25)."""
import ast
from pathlib import Path

import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.text import shape_words as sw
from shapemove.core.text.shape_words import parse_shape_words

ROOT = Path(__file__).resolve().parents[1]


def test_the_reader_is_a_leaf_and_the_only_definition():
    tree = ast.parse((ROOT / "core" / "text" / "shape_words.py").read_text())
    project = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.level}
    assert project == {"errors"}
    from shapemove.core.data import shape_text

    assert shape_text.ADJECTIVES is sw.ADJECTIVES and shape_text.parse_shape_text is sw.parse_shape_text
    for w, (h, r) in sw.SIZE_TARGETS.items():   # what the fit aims at lies inside the caption's ranges
        h_rng, r_rng = sw.ADJECTIVES[w]
        assert h is None or h_rng[0] <= h < h_rng[1], w
        assert r is None or r_rng[0] <= r < r_rng[1], w


@pytest.mark.parametrize("text, want", [
    ("a muscular 188 cm man, 92 kg", dict(gender=0.0, muscle=0.85, height_cm=188.0, mass_kg=92.0)),
    ("a woman", dict(gender=1.0, age=None)),
    ("she is 1,68 m and 60 kg", dict(gender=1.0, height_cm=168.0, mass_kg=60.0)),
    ("a 6 ft 4, 250 lb man", dict(gender=0.0, height_cm=76 * 2.54, mass_kg=250 * 0.45359237)),
    ("6'2\" guy", dict(gender=0.0, height_cm=74 * 2.54)),
    ("he stands 6-foot-2", dict(height_cm=74 * 2.54)),
    ("74 inches tall", dict(height_cm=74 * 2.54)),
    ("14 st 4 lb, 5 ft 9", dict(mass_kg=14 * 6.35029318 + 4 * 0.45359237, height_cm=69 * 2.54)),
    ("a 35-year-old powerlifter, BMI 31", dict(age=35.0, muscle=0.92, bmi=31.0)),
    ("a man in his early 40s", dict(gender=0.0, age=42.0)),
    ("in her late sixties", dict(gender=1.0, age=68.0)),
    ("an elderly lady", dict(gender=1.0, age=75.0)),
    ("a slim teenage girl", dict(gender=1.0, age=16.0, weight=0.25)),
    ("a grandmother", dict(gender=1.0, age=72.0, age_implied=True)),
    ("a middle-aged, heavy-set guy", dict(gender=0.0, age=48.0, weight=0.85)),
    ("a ripped young woman", dict(gender=1.0, age=24.0, muscle=0.95)),
    ("a young girl", dict(gender=1.0, age=16.0)),       # the noun's age, young, wins over young's 24
    ("170-180 cm tall", dict(height_cm=175.0)),
])
def test_words_and_numbers(text, want):
    d = parse_shape_words(text)
    for k, v in want.items():
        got = getattr(d, k)
        assert (got == pytest.approx(v)) if isinstance(v, float) else got == v, (k, got)


def test_size_words_and_girths():
    d = parse_shape_words("a tall, heavy-set man with a 40-inch waist")
    assert d.size_words == ["tall", "heavy-set"] and d.girths == {"waist_cm": pytest.approx(101.6)}
    assert sw.size_targets(d) == (185.0, 0.565)
    assert sw.size_targets(parse_shape_words("very tall and stocky")) == (195.0, 0.565)  # height word wins
    assert parse_shape_words("a 160 cm tall woman").size_words == []   # "cm tall" is a number, no size word
    assert parse_shape_words("a person nods").words == [] and not parse_shape_words("someone with broad shoulders")


@pytest.mark.parametrize("text, match", [
    ("an obese 2 m, 40 kg man", r"BMI of 10\.0.*\"obese\" means BMI >= 29"),
    ("weighs 900 kg", "no person is 900 kg"),
    ("a 2 cm man", "no person is 2 cm tall"),
    ("a skinny man, 190 cm, 110 kg", r"BMI 30\.5, but \"skinny\" means BMI <= 21"),
    ("an elderly 25-year-old", "'elderly' .* and 25 years old"),
    ("a tall 150 cm man", "'tall' .* and 150 cm tall disagree"),
    ("a man and a woman", "names a man and a woman"),
    ("slim and chubby", "build words disagree: 'slim' and 'chubby'"),
    ("a muscular, frail man", "build words disagree: 'muscular' and 'frail'"),
    ("a tall short guy", "height words disagree"),
    ("young and elderly", "age words disagree"),
    ("a 5-year-old boy", "child"),
    ("weighs 90", "cannot read the number"),
    ("180 cm, 2 m tall", "two different heights"),
    ("BMI 30, 180 cm, 60 kg", "BMI 30 disagrees"),
    ("someone -1.8 m tall", "negative number"),
])
def test_contradictions_and_impossible_bodies_are_named(text, match):
    with pytest.raises(ShapeMoveError, match=match):
        parse_shape_words(text)


def test_motion_captions_keep_their_numbers_lenient():
    for motion in ("a person walks 5 m forward", "turns 180 degrees", "jumps 30 centimeters forward"):
        assert sw.parse_shape_text(motion) == {}
    assert sw.parse_shape_text("A person, 1.86 m tall with a 99 cm waist, jogs.") == {
        "height_cm": pytest.approx(186.0), "waist_cm": 99.0}
