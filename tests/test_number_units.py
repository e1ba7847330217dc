"""The unit reader of the `[BETA]` head (meets 3, ``core/models/number_units.py``): its training
labels come from the bodies' own sizes, its choice sums the numbers in the units' own scales, and
`train head` can teach it alone on top of a trained head that stays as it was."""
import json

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.models.number_units import UNITS, NumberUnits, unit_labels
from tiny_models import tiny_bundle  # noqa: F401  (fixture)


def names(labels):
    return [UNITS[i][0] for i in labels]


def test_unit_labels_are_the_units_that_add_up_to_the_body():
    # hand-derived: 6 x 30.48 + 2 x 2.54 = 187.96 cm; 200 x 0.4536 = 90.72 kg
    assert names(unit_labels([6, 2, 200], 187.5, 90.9)) == ["ft", "in", "lb"]
    # 14 st 4 lb = 14 x 6.350 + 4 x 0.4536 = 90.72 kg; 5 ft 11 = 180.34 cm; the order is the text's
    assert names(unit_labels([14, 4, 5, 11], 180.0, 90.7)) == ["st", "lb", "ft", "in"]
    assert names(unit_labels([1.88, 92], 188.2, 92.3)) == ["m", "kg"]
    # girths and an age state neither size
    assert names(unit_labels([189, 122, 92, 109], 189.2, 70.0)) == ["cm", "none", "none", "none"]
    assert names(unit_labels([43], 170.0, 60.0)) == ["none"]
    # a number a unit would put off by more than rounding is not read: 180 cm for a 175 cm body
    assert names(unit_labels([180, 80], 175.0, 80.2)) == ["none", "kg"]
    # "1,88 m": metres and centimetres in a row
    assert names(unit_labels([1, 88], 188.3, 70.0)) == ["m", "cm"]


def _numbers(values_at: dict, L: int) -> torch.Tensor:
    from shapemove.core.models.text_numbers import value_features

    f = torch.zeros(1, L, 6)
    for i, v in values_at.items():
        f[0, i] = torch.tensor(value_features(v))
    return f


class ByValue(torch.nn.Module):
    """A stand-in chooser for the test: the unit by the number's value alone (the window's feature
    3 from the end is value / 100): under 3 m, under 12 in, under 30 ft, under 120 kg, else lb."""

    def forward(self, window):
        v = window[..., -3] * 100.0
        pick = torch.where(v < 3, 2, torch.where(v < 12, 5, torch.where(v < 30, 4, torch.where(v < 120, 6, 7))))
        return 20.0 * torch.nn.functional.one_hot(pick, len(UNITS)).float()


def test_the_chosen_units_sum_the_numbers_and_the_guess_stands_in():
    assert [UNITS[i][0] for i in (2, 4, 5, 6, 7)] == ["m", "ft", "in", "kg", "lb"]
    units = NumberUnits(text_dim=8, width=4, hidden=8).eval()
    units.choose = ByValue()
    text, guess = torch.zeros(1, 6, 8), torch.tensor([[170.0, 65.0]])
    numbers = _numbers({1: 6.0 + 0.0, 3: 2.0, 5: 200.0}, 6)
    numbers[0, 1] = _numbers({0: 16.0}, 1)[0, 0]   # 16 "ft" (the rule's), 2 in, 200 lb
    said = units(guess, text, numbers)
    assert units.read_units(text, numbers)[0] == [(16.0, "ft"), (2.0, "m"), (200.0, "lb")]
    # hand-derived: 16 x 30.48 + 2 x 100 cm; 200 x 0.45359237 kg
    assert torch.allclose(said, torch.tensor([[16 * 30.48 + 200.0, 90.718474]]), atol=1e-3)
    # no numbers: the guess, untouched
    assert torch.equal(units(guess, text, torch.zeros(1, 6, 6)), guess)
    # a number spelt in three word pieces ("1.88") counts once; a mass alone keeps the guessed height
    three = _numbers({1: 1.88, 2: 1.88, 3: 1.88, 5: 80.0}, 6)
    assert torch.allclose(units(guess, text, three), torch.tensor([[188.0, 80.0]]), atol=1e-3)
    # in training the choice is the softmax's mixture, with a gradient
    units.train()
    assert torch.allclose(units(guess, text, three), torch.tensor([[188.0, 80.0]]), atol=1e-3)


def test_a_reader_without_values_chooses_from_the_words_around_the_number_alone():
    """values=False: neither the number's value nor its own word pieces change the choice, the
    words around it do."""
    torch.manual_seed(0)
    units = NumberUnits(text_dim=8, width=4, hidden=8, values=False).eval()
    text = torch.randn(1, 6, 8)
    a, b = _numbers({2: 9.0}, 6), _numbers({2: 20.0}, 6)
    other = text.clone()
    other[0, 2] = torch.randn(8)            # another number's word piece in its place
    la = units.logits(text, a)[0][0, 2]
    assert torch.allclose(la, units.logits(other, b)[0][0, 2])
    moved = text.clone()
    moved[0, 3] = torch.randn(8)            # the word after it
    assert not torch.allclose(la, units.logits(moved, a)[0][0, 2])


def test_a_fresh_reader_reads_every_number_as_none():
    units = NumberUnits(text_dim=8, width=4, hidden=8).eval()
    numbers = _numbers({0: 188.0, 2: 92.0}, 4)
    guess = torch.tensor([[160.0, 55.0]])
    assert torch.equal(units(guess, torch.randn(1, 4, 8), numbers), guess)


@pytest.fixture(scope="module")
def trained_text_head(tiny_bundle, tmp_path_factory):
    from shapemove.core.train.train_head import HeadTrainConfig, train_head

    model_dir, data = tiny_bundle
    out = tmp_path_factory.mktemp("head") / "run"
    train_head(model_dir, data, out, HeadTrainConfig.tiny(), verbose=False)
    return out / "model", data


@pytest.mark.usefixtures("one_thread")
def test_train_head_teaches_the_unit_reader_alone_on_a_trained_head(trained_text_head, tmp_path):
    """start_from_source + train_only ["units"]: every weight the source head has is the same after
    training; the reader's weights moved; a text without numbers gives the source's betas."""
    from safetensors.torch import load_file

    from shapemove.core.models.shapemove_t5 import ShapeMoveT5
    from shapemove.core.train.train_head import HeadTrainConfig, train_head

    source, data = trained_text_head
    c = HeadTrainConfig.tiny()
    c.head = {**c.head, "numbers": 6, "number_tokens": 0, "meets": 3}
    c.start_from_source, c.train_only, c.stated_share, c.pool = True, ["units"], 1.0, 60
    res = train_head(source, data, tmp_path / "run", c, verbose=False)
    assert res["step"] == c.steps
    before = load_file(str(source / "t5" / "beta_head.safetensors"))
    after = load_file(str(tmp_path / "run" / "model" / "t5" / "beta_head.safetensors"))
    assert set(before) < set(after)
    for k, v in before.items():
        assert torch.equal(after[k], v), k
    fresh = NumberUnits(384, features=6).state_dict()
    assert any(not torch.equal(after["units." + k], v) for k, v in fresh.items() if "choose.2" in k)
    info = json.loads((tmp_path / "run" / "model" / "t5" / "shapemove.json").read_text())["beta_head"]
    assert info["meets"] == 3 and info["number_tokens"] == 0
    t_old, r_old = ShapeMoveT5.load(source / "t5")
    t_new, r_new = ShapeMoveT5.load(tmp_path / "run" / "model" / "t5")
    texts, shapes = ["a person walks."] * 3, ["an elderly woman", None, "a tall muscular man"]
    with torch.no_grad():
        old = t_old.predict_betas(t_old.inputs_for(r_old, texts, shapes))
        new = t_new.predict_betas(t_new.inputs_for(r_new, texts, shapes))
    assert torch.allclose(old, new, atol=1e-4)


def test_train_head_refuses_a_source_head_of_other_sizes_and_unknown_parts(trained_text_head, tmp_path):
    from shapemove.core.train.train_head import HeadTrainConfig, train_head

    source, data = trained_text_head
    c = HeadTrainConfig.tiny()
    c.head = {**c.head, "width": 16, "meets": 3, "numbers": 6}
    c.start_from_source = True
    with pytest.raises(ShapeMoveError, match="does not fit the new head's sizes"):
        train_head(source, data, tmp_path / "a", c, verbose=False)
    c = HeadTrainConfig.tiny()
    c.train_only = ["pointer"]
    with pytest.raises(ShapeMoveError, match="no part pointer"):
        train_head(source, data, tmp_path / "b", c, verbose=False)
    with pytest.raises(ShapeMoveError, match="meets 3 reads the numbers"):
        from shapemove.core.models.beta_head import build_head
        build_head({"kind": "text", "sliders": 6, "meets": 3}, 16)


def test_the_default_head_meets_stated_sizes_and_leaves_words_alone(openbody):
    """The shipped head (meets 3): sizes in several units land on the mesh (``fast_measure``:
    top-to-bottom height, volume x density mass), hand-converted; a text without numbers gives the
    betas of the same head with no unit reader at all."""
    from shapemove.core.body.shape_from_measurements import fast_measure
    from shapemove.core.models.beta_head import build_head
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    t5, reader = ShapeMoveT5.load("weights/default/t5")
    assert t5.info["beta_head"]["meets"] == 3
    texts = ["she is 5'7 and 140 lbs", "a big guy, 1.92 m, 101 kg", "13 st 3 lb, 170cm", "an elderly woman",
             "a muscular young man"]
    want = [(5 * 30.48 + 7 * 2.54, 140 * 0.45359237), (192.0, 101.0), (170.0, 13 * 6.35029318 + 3 * 0.45359237)]
    with torch.no_grad():
        inputs = t5.inputs_for(reader, ["a person walks."] * len(texts), texts)
        betas = t5.predict_betas(inputs)
        plain = {k: v for k, v in t5.beta_head.config().items() if k not in ("meets", "numbers", "number_tokens")}
        words_only = build_head(plain, t5.d_model)
        words_only.load_state_dict({k: v for k, v in t5.beta_head.state_dict().items()
                                    if k in words_only.state_dict()})
        states, mask, _ = t5.head_text(inputs)
        old = words_only(t5.beta_state(inputs), states, mask)
    got = fast_measure(openbody, betas.numpy(), ("height_cm", "mass_kg"))
    for (h, kg), (gh, gkg) in zip(want, got[:3]):
        assert abs(gh - h) < 0.3 and abs(gkg - kg) < 0.3, (h, kg, gh, gkg)
    assert torch.allclose(betas[3:], old[3:], atol=1e-5)
    assert not torch.allclose(betas[:3], old[:3], atol=1e-2)


def test_the_default_head_refuses_sizes_no_body_has():
    """Sizes the head reads that it cannot make, or no living body has, are a clear error naming
    them, never a body clamped to something else; a heavy but possible body is made."""
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    t5, reader = ShapeMoveT5.load("weights/default/t5")

    def betas(text):
        with torch.no_grad():
            return t5.predict_betas(t5.inputs_for(reader, ["a person walks."], [text]))

    for text, said in [("a man who weighs 900 kg", "weight of 900 kg"), ("a woman, 120 cm", "height of 120 cm"),
                       ("an obese 2 m, 40 kg man", "BMI of 10.0")]:
        with pytest.raises(ShapeMoveError, match=said):
            betas(text)
    assert betas("a woman, 150 cm, 150 kg").shape == (1, 10)


def test_generate_refuses_an_impossible_head_reading_before_any_motion():
    """A batch whose second request's shape text the head reads as no body stops before the first
    is generated (every text is checked first), with the head's message."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    calls = []
    gen.tokens_for = lambda reqs: calls.append(reqs) or (_ for _ in ()).throw(AssertionError("generated"))
    reqs = [Request("a person walks forward", "a man, 180 cm", seconds=2, shape_from="head"),
            Request("a person waves", "a man who weighs 900 kg", seconds=2, shape_from="head")]
    with pytest.raises(ShapeMoveError, match="weight of 900 kg"):
        gen.generate_batch(reqs, progress=None)
    assert calls == []


def test_the_evaluation_counts_a_text_the_head_refuses_as_refused():
    from shapemove.core.eval.shape_eval import head_betas, head_readings
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    t5, reader = ShapeMoveT5.load("weights/default/t5")
    texts = ["a man, 180 cm", "a man who weighs 900 kg", "an elderly woman"]
    betas, refused = head_readings(t5, reader, ["a person walks."] * 3, texts)
    assert np.isnan(betas[1]).all() and not np.isnan(betas[[0, 2]]).any()
    assert refused == [(texts[1], refused[0][1])] and "900 kg" in refused[0][1]
    alone = head_betas(t5, reader, ["a person walks."] * 2, [texts[0], texts[2]])
    assert np.allclose(betas[[0, 2]], alone, atol=1e-5)


def test_what_the_head_read_is_said_in_the_units_typed():
    from shapemove.core.generation.generate import Generator
    from shapemove.core.models.number_units import describe

    assert describe([(6.0, "ft"), (2.0, "in"), (200.0, "lb"), (35.0, "none")]) == "6 ft 2 in = 188.0 cm; 200 lb = 90.7 kg"
    assert describe([(35.0, "none")]) == ""
    gen = Generator(None)
    assert gen.head_reading("a person walks", "she is 1.62 m, 9 st 4 lb") == "1.62 m = 162.0 cm; 9 st 4 lb = 59.0 kg"
    assert gen.head_reading("a person walks", "an elderly woman") is None
    assert gen.head_reading("a person walks", None) is None
