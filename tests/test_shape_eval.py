"""eval shape (core/eval/shape_eval.py): the [BETA] head on new bodies' shape texts."""
import numpy as np
import pytest
import torch

from shapemove.core.eval.shape_eval import eval_shape, head_betas, text_form


def test_text_forms():
    assert text_form("A person standing 170 cm tall, with a chest circumference of 98 cm, a waist circumference of "
                     "70 cm, a hip circumference of 94 cm, an arm length of 48 cm and a leg length of 90 cm.") == "sentence"
    assert text_form("5'7\" tall with a 28-inch waist") == "feet and inches"
    assert text_form("5 ft 7 in tall, waist 28 inches") == "feet and inches"
    assert text_form("1.70 m tall, waist 73 cm") == "metres"
    assert text_form("height 168 cm, waist 70 cm") == "centimetres"


def test_head_betas_are_the_decoders_betas_and_the_eval_adds_up():
    from shapemove.core.generation.model_bundle import model_files, resolve_model_dir
    from shapemove.core.models.constrained_decoding import decode
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    t5, reader = ShapeMoveT5.load(model_files(resolve_model_dir(None))["t5"])
    caps, shapes = ["a person walks forward.", "someone jumps."], ["1.90 m tall, waist 100 cm", "a petite woman"]
    got = head_betas(t5, reader, caps, shapes)
    want = decode(t5, t5.inputs_for(reader, caps, shapes), 1, 2, temperature=0).betas.numpy()
    assert np.allclose(got, want, atol=1e-5)
    res = eval_shape(None, bodies=3, seed=1, progress=False)
    n = res["numeric"]
    per = [d for d in n["per_form"].values() if d["texts"]]
    assert n["texts"] == sum(d["texts"] for d in per) >= 6  # the sentence + at least one short form per body
    assert n["height_err_cm"] == pytest.approx(sum(d["texts"] * d["height_err_cm"] for d in per) / n["texts"])
    assert 0 <= n["height_err_cm"] < 10 and 0 <= n["waist_err_cm"] < 15
    words = res["adjectives"]["per_word"]
    assert set(words) >= {"tall", "petite", "stocky"} and all(d["n"] == 3 for d in words.values())
    assert words["very tall"]["height_cm"] > words["very short"]["height_cm"] + 10  # the head reads the words
    with pytest.raises(Exception, match="bodies"):
        eval_shape(None, bodies=0)
    assert torch.is_tensor(t5.predict_betas(t5.inputs_for(reader, caps[:1], shapes[:1])))
