"""The values of the numbers in a shape text, beside its word pieces (core/models/text_numbers.py), and
a `[BETA]` head that reads them (``TextBetaHead(numbers=F)``, ``ShapeMoveT5.inputs_for``)."""
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from tiny_models import tiny_bundle  # noqa: F401  (fixture)

pytestmark = pytest.mark.usefixtures("one_thread")


@pytest.fixture(scope="module")
def tokenizer():
    from shapemove.core.models.text_encoder import load_text_encoder

    return load_text_encoder().tokenizer


def test_each_token_carries_the_value_of_the_number_it_spells(tokenizer):
    from shapemove.core.models.text_numbers import FEATURES, number_features

    texts = ["a man, 6 ft 2, 200 lb", "she is 1.88 m", "a grandmother"]
    feats = number_features(tokenizer, texts)
    for t, f in zip(texts, feats):
        enc = tokenizer.encode(t)
        assert f.shape == (len(enc.ids), FEATURES)
        values = {tok: round(float(r[3]) * 100, 4) for tok, r in zip(enc.tokens, f) if r[0] == 1.0}
        if t.startswith("a man"):
            assert values == {"6": 6.0, "2": 2.0, "200": 200.0}
        elif t.startswith("she"):
            assert values == {"1": 1.88, ".": 1.88, "88": 1.88}   # the three pieces of 1.88, one value
        else:
            assert not values
        assert f[0].abs().sum() == 0 and f[-1].abs().sum() == 0   # [CLS] and [SEP]
    # hand-derived scales of 200: flag, tanh(20), tanh(2), 2.0, tanh(0.2), log10(201)/3
    row = feats[0][[tok for tok in tokenizer.encode(texts[0]).tokens].index("200")]
    assert torch.allclose(row, torch.tensor([1.0, 1.0, 0.96402758, 2.0, 0.19737532, 0.76773018]), atol=1e-5)


def test_a_head_that_reads_numbers_sees_the_value_and_refuses_without_it():
    from shapemove.core.models.beta_head import build_head

    torch.manual_seed(0)
    head = build_head({"kind": "text", "hidden": 32, "width": 32, "queries": 2, "heads": 2, "numbers": 6}, 16)
    assert head.reads_numbers and head.config()["numbers"] == 6
    h, text = torch.randn(1, 16), torch.randn(1, 5, 384)
    mask = torch.ones(1, 5, dtype=torch.bool)
    n1, n2 = torch.zeros(1, 5, 6), torch.zeros(1, 5, 6)
    n1[0, 2, 0], n1[0, 2, 3] = 1.0, 1.80
    n2[0, 2, 0], n2[0, 2, 3] = 1.0, 1.50
    assert not torch.allclose(head(h, text, mask, n1), head(h, text, mask, n2))   # same words, other value
    with pytest.raises(ShapeMoveError, match="number features"):
        head(h, text, mask)
    assert head(h).shape == (1, 10)   # no shape text: no numbers needed


def test_the_t5_hands_a_numbers_head_its_features_and_its_encoder_the_same_inputs(tiny_bundle):
    from shapemove.core.models.beta_head import build_head
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5
    from shapemove.core.models.text_numbers import number_features

    model_dir, _ = tiny_bundle
    t5, reader = ShapeMoveT5.load(model_dir / "t5")
    motions, shapes = ["a person walks forward.", "someone waves."], ["a man, 180 cm, 80 kg", None]
    plain = t5.inputs_for(reader, motions, shapes)
    enc0, _ = t5.encode(*plain)
    torch.manual_seed(0)
    t5.beta_head = build_head({"kind": "text", "hidden": 32, "width": 32, "queries": 2, "heads": 2, "numbers": 6},
                              t5.d_model)
    inputs = t5.inputs_for(reader, motions, shapes)
    assert len(inputs) == len(plain) + 1
    enc1, _ = t5.encode(*inputs)
    assert torch.equal(enc0, enc1)   # the encoder never sees the number features
    states, mask, numbers = t5.head_text(inputs)
    want = number_features(reader.tokenizer, [shapes[0]])[0]
    assert torch.equal(numbers[0, :len(want)], want) and numbers[0, len(want):].abs().sum() == 0
    assert numbers[1].abs().sum() == 0 and int(mask[0].sum()) == len(want)
    assert t5.predict_betas(inputs).shape == (2, 10)


def test_the_pointer_counts_each_number_once_and_stands_in_for_the_guess():
    """``TextBetaHead._point`` (meets 2): a number spelt in several word pieces ("1.88") counts once;
    gates that add up past 1 leave nothing of the words' guess; no number leaves the guess as it is."""
    from shapemove.core.models.beta_head import build_head
    from shapemove.core.models.text_numbers import number_features

    head = build_head({"kind": "text", "hidden": 32, "width": 32, "queries": 2, "heads": 2, "sliders": 6,
                       "numbers": 6, "meets": 2}, 16)
    with torch.no_grad():
        head.pointer.weight.zero_()
        head.pointer.bias.copy_(torch.tensor([30.0, -30.0, float(torch.log(torch.tensor(100.0))), 0.0]))
    from shapemove.core.models.text_encoder import load_text_encoder

    tok = load_text_encoder().tokenizer
    texts = ["she is 1.88 m", "6 ft 2", "a tall woman"]
    feats = number_features(tok, texts)
    L = max(len(f) for f in feats)
    numbers = torch.zeros(3, L, 6)
    for i, f in enumerate(feats):
        numbers[i, :len(f)] = f
    guess = torch.tensor([[170.0, 70.0]] * 3)
    said = head._point(guess, torch.zeros(3, L, 32), numbers)
    # height: every number's first piece, gate 1, scale 100; mass: gates 0, the guess
    assert torch.allclose(said[:, 0], torch.tensor([188.0, 800.0, 170.0]), atol=1e-3)
    assert torch.allclose(said[:, 1], torch.tensor([70.0, 70.0, 70.0]), atol=1e-3)
