"""The ShapeMove T5: tokenizer with motion tokens, [BETA] head, constrained decoding, save/load."""
from pathlib import Path

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.generation.prompts import check_prompt
from shapemove.core.models.constrained_decoding import decode
from shapemove.core.models.shapemove_t5 import ShapeMoveT5, T5Size, shapemove_prompt
from shapemove.core.models.tokenizer import (BETA, EOM, MOTION_TOKENS, SOM, MotionVocab, load_tokenizer,
                                             tokenizer_from_sentencepiece, train_sentencepiece)

TEXTS = ["A person walks forward.", "Someone waves with the left hand.", "An elderly person runs in a circle.",
         "A male standing 182 cm tall, with a chest circumference of 101 cm and a waist circumference of 90 cm.",
         "a tall, heavy-set man", "The person demonstrates a motion like: kicks forward with the left leg."] * 30


@pytest.fixture(scope="module")
def tok(tmp_path_factory):
    d = tmp_path_factory.mktemp("tok")
    return tokenizer_from_sentencepiece(train_sentencepiece(TEXTS, d / "sp", vocab_size=200))


@pytest.fixture(scope="module")
def model(tok):
    torch.manual_seed(0)
    return ShapeMoveT5.build(tok, T5Size.tiny()).eval()


def test_tokenizer_round_trip_with_added_tokens(tok, tmp_path):
    vocab = MotionVocab(tok)
    assert len(tok) == vocab.first_code_id + 1000 + 3
    codes = [0, 7, 999, 500]
    ids = vocab.target_ids(codes)
    assert tok.convert_ids_to_tokens(ids) == [BETA, SOM, "[MID_0]", "[MID_7]", "[MID_999]", "[MID_500]", EOM, "</s>"]
    assert vocab.ids_to_codes(ids) == codes
    # added tokens are single ids inside text, and text survives encode/decode (case-folded)
    enc = tok("A person waves. [BETA][SOM][MID_42][EOM]").input_ids
    assert [i for i in enc if i >= vocab.first_code_id] == [vocab.beta_id, vocab.som_id, vocab.first_code_id + 42, vocab.eom_id]
    assert tok.decode(enc, skip_special_tokens=True).strip() == "a person waves."
    tok.save_pretrained(str(tmp_path))
    again = load_tokenizer(tmp_path)
    assert again("A PERSON waves. [MID_42]").input_ids == tok("a person waves. [MID_42]").input_ids
    assert again.convert_tokens_to_ids(MOTION_TOKENS) == tok.convert_tokens_to_ids(MOTION_TOKENS)


def test_constrained_decoding_never_emits_text_in_motion_span(model, tok):
    enc = tok([shapemove_prompt(t) for t in TEXTS[:4]], return_tensors="pt", padding=True)
    g = torch.Generator().manual_seed(1)
    for temperature in (0.0, 1.0, 3.0):
        out = decode(model, (enc.input_ids, enc.attention_mask), min_codes=5, max_codes=12, temperature=temperature,
                     generator=g)
        for ids, codes in zip(out.token_ids, out.codes):
            assert ids[0] == model.vocab.beta_id and ids[1] == model.vocab.som_id
            span = ids[2: ids.index(model.vocab.eom_id)]
            assert all(model.vocab.is_code(i) for i in span)
            assert 5 <= len(codes) <= 12 and len(codes) == len(span)
        assert out.betas.shape == (4, 10)


def test_beta_projection_gets_gradient(model, tok):
    m = ShapeMoveT5.build(tok, T5Size.tiny()).train()
    enc = tok([shapemove_prompt("a person walks", "a tall man")] * 2, return_tensors="pt", padding=True)
    labels = torch.tensor([m.vocab.target_ids([1, 2, 3])] * 2)
    out = m(enc.input_ids, enc.attention_mask, labels, torch.ones(2, 10))
    out["loss"].backward()
    assert out["l1"] > 0
    assert m.beta_head.net[0].weight.grad.abs().sum() > 0
    # and the gradient reaches the decoder through the [BETA] state
    assert m.lm.decoder.block[0].layer[0].SelfAttention.q.weight.grad.abs().sum() > 0


def test_save_load_round_trip_via_plain_transformers(model, tok, tmp_path):
    from transformers import T5ForConditionalGeneration

    model.save(tmp_path / "t5", tok, meta={"vae": "none"})
    plain = T5ForConditionalGeneration.from_pretrained(str(tmp_path / "t5"), local_files_only=True)
    assert plain.config.vocab_size == len(tok)
    sd = model.lm.state_dict()
    for k, v in plain.state_dict().items():
        assert torch.equal(v, sd[k]), k
    again, tok2 = ShapeMoveT5.load(tmp_path / "t5")
    enc = tok(["a person walks forward."], return_tensors="pt")
    a = decode(model, (enc.input_ids, enc.attention_mask), 3, 6, temperature=0)
    b = decode(again, (enc.input_ids, enc.attention_mask), 3, 6, temperature=0)
    assert a.codes == b.codes and torch.allclose(a.betas, b.betas)
    with pytest.raises(ShapeMoveError, match="not a ShapeMove T5"):
        ShapeMoveT5.load(tmp_path)


@pytest.mark.parametrize("bad, match", [
    ("", "empty"), ("   \n", "empty"), ("x" * 10_000, "10000 characters"),
    ("a person\x00 walks", "control"), ("walk\u200b", "control"), ("12345 !!", "no words"),
])
def test_bad_prompts_give_clear_errors(bad, match):
    with pytest.raises(ShapeMoveError, match=match):
        check_prompt(bad)


def test_good_prompt_is_tidied():
    assert check_prompt("  a person\n walks   forward ") == "a person walks forward"


def test_build_on_a_local_pretrained_t5_folder(tok, tmp_path):
    """A user's pretrained T5 on disk (here a small one saved with plain transformers): its weights
    are kept, the embeddings grow for the motion tokens, nothing is fetched."""
    from transformers import T5Config, T5ForConditionalGeneration

    base_tok = tokenizer_from_sentencepiece(train_sentencepiece(TEXTS, tmp_path / "sp", vocab_size=150))
    n_text = base_tok.convert_tokens_to_ids("[MID_0]")  # the plain vocabulary before our tokens
    cfg = T5Config(vocab_size=n_text, d_model=32, d_ff=64, num_layers=1, num_decoder_layers=1, num_heads=2, d_kv=16,
                   decoder_start_token_id=0)
    torch.manual_seed(3)
    plain = T5ForConditionalGeneration(cfg)
    plain.save_pretrained(str(tmp_path / "base"))
    m = ShapeMoveT5.build(base_tok, base_model=tmp_path / "base")
    assert m.lm.get_input_embeddings().weight.shape[0] == len(base_tok) == n_text + 1003
    torch.testing.assert_close(m.lm.get_input_embeddings().weight[:n_text], plain.get_input_embeddings().weight)
    enc = base_tok(["a person walks forward."], return_tensors="pt")
    out = m(enc.input_ids, enc.attention_mask, torch.tensor([m.vocab.target_ids([5, 6])]), torch.zeros(1, 10))
    assert torch.isfinite(out["loss"])
    with pytest.raises(ShapeMoveError, match="not a pretrained T5"):
        ShapeMoveT5.build(base_tok, base_model=tmp_path)


def test_text_to_motion_and_motion_to_text_examples_from_real_clips(tiny_dataset):
    """The T5 training examples: the paper's prompt format with [BETA] targets and betas, and with
    m2t_share the reverse task (motion tokens in, caption out); both batch and give a finite loss."""
    import random

    from shapemove.core.models.savae import SAVAE, SAVAEConfig
    from shapemove.core.models.tokenizer import MotionVocab
    from shapemove.core.train.motion_dataset import load_stats, read_split
    from shapemove.core.train.t5_dataset import T2MExamples, all_texts, collate, tokenize_clips

    torch.manual_seed(0)
    vae = SAVAE(SAVAEConfig(width=16, depth=1, shape_hidden=16), *load_stats(tiny_dataset))
    ids = read_split(tiny_dataset, "train")
    tokens = tokenize_clips(vae, tiny_dataset, ids)
    n = np.load(tiny_dataset / "norm_joint_vecs" / f"{ids[0]}.npy").shape[0]
    assert len(tokens[ids[0]]) == n // 4 and tokens[ids[0]].max() < 1000
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        tok = tokenizer_from_sentencepiece(train_sentencepiece(all_texts(tiny_dataset, ids), Path(d) / "sp", 300))
    vocab = MotionVocab(tok)
    rng = random.Random(0)
    t2m = [T2MExamples(tiny_dataset, "train", tokens, max_codes=8).sample(rng) for _ in range(6)]
    assert all("The person demonstrates a motion like:" in e["input"] and 1 <= len(e["codes"]) <= 8 for e in t2m)
    m2t = [T2MExamples(tiny_dataset, "train", tokens, max_codes=8, m2t_share=1.0).sample(rng) for _ in range(6)]
    assert all(e["input"].startswith("Describe the motion: [SOM]") and e["codes"] is None and e["text"] for e in m2t)
    model = ShapeMoveT5.build(tok, T5Size.tiny())
    for batch in (t2m, m2t, t2m[:3] + m2t[:3]):
        ids_, attn, labels, betas = collate(batch, tok, vocab)
        out = model(ids_, attn, labels, betas)
        assert torch.isfinite(out["loss"])
    # motion-to-text rows have no [BETA]: only the text-to-motion rows feed the betas loss
    ids_, attn, labels, betas = collate(m2t, tok, vocab)
    assert not (labels == vocab.beta_id).any() and model(ids_, attn, labels, betas)["l1"] == 0


# -- the default encoder: frozen pretrained MiniLM + T5 decoder ---------------------------------
def _minilm_batch(model, enc, pairs):
    from shapemove.core.models.text_encoder import StateCache

    cache = StateCache(enc)
    inputs = model.inputs_for(cache, [m for m, _ in pairs], [s for _, s in pairs])
    return inputs


@pytest.fixture(scope="module")
def minilm():
    from shapemove.core.models.text_encoder import load_text_encoder

    return load_text_encoder()


def test_minilm_inputs_put_the_shape_text_first(minilm):
    m = ShapeMoveT5.build_minilm(1000, T5Size.tiny())
    x, mask, seg = m.inputs_for(minilm, ["a person walks", "someone kicks a ball hard"], ["a tall man", None])
    ref_s, ms = minilm.states(["a tall man"])
    ref_m, mm = minilm.states(["a person walks", "someone kicks a ball hard"])
    ns, nm0, nm1 = int(ms[0].sum()), int(mm[0].sum()), int(mm[1].sum())
    assert mask[0].sum() == ns + nm0 and mask[1].sum() == nm1
    assert (seg[0, :ns] == 0).all() and (seg[0, ns:] == 1).all() and (seg[1] == 1).all()
    torch.testing.assert_close(x[0, :ns], ref_s[0, :ns])
    torch.testing.assert_close(x[0, ns:ns + nm0], ref_m[0, :nm0])
    torch.testing.assert_close(x[1, :nm1], ref_m[1, :nm1])


def test_minilm_vocabulary_comes_from_the_fsq():
    from shapemove.core.models.fsq import FSQ

    for levels in ((8, 5, 5, 5), (5, 5, 5)):
        n = FSQ(levels).codebook_size
        m = ShapeMoveT5.build_minilm(n, T5Size.tiny())
        assert m.vocab.num_codes == n and m.lm.lm_head.out_features == n + 5
        assert m.vocab.ids_to_codes(m.vocab.target_ids([0, n - 1])) == [0, n - 1]


def test_minilm_decoder_learns_prompts_codes_and_betas(minilm, tmp_path):
    """Overfit two prompts: greedy decoding (with the key/value cache) gives back each prompt's own
    codes and betas; after save/load the same."""
    torch.manual_seed(0)
    m = ShapeMoveT5.build_minilm(1000, T5Size.tiny()).train()
    pairs = [("a person walks forward", None), ("someone kicks with the right foot", "a very tall heavy man")]
    targets = [[11, 12, 13, 14, 15], [900, 7, 7]]
    betas = torch.tensor([[1.0] + [0.0] * 9, [-1.5, 0.5] + [0.0] * 8])
    x, mask, seg = m.inputs_for(minilm, [p for p, _ in pairs], [s for _, s in pairs])
    L = max(len(t) for t in targets) + 4
    labels = torch.full((2, L), -100)
    for i, t in enumerate(targets):
        ids = m.vocab.target_ids(t)
        labels[i, : len(ids)] = torch.tensor(ids)
    opt = torch.optim.Adam(m.parameters(), lr=3e-3)
    for _ in range(300):
        out = m(x, mask, labels, betas, seg)
        opt.zero_grad()
        out["loss"].backward()
        opt.step()
    assert out["ce"] < 0.05 and out["l1"] < 0.1, out
    m.eval()
    d = decode(m, (x, mask, seg), 1, 10, temperature=0)
    assert d.codes == targets
    torch.testing.assert_close(d.betas, betas, atol=0.15, rtol=0)
    # the cached decoder equals running the whole sequence again
    enc, emask = m.encode(x, mask, seg)
    full, _, _ = m.step(enc, emask, torch.tensor([[0] + r for r in (d.token_ids[0][:4], d.token_ids[1][:4])]))
    step_logits, _, past = m.step(enc, emask, torch.tensor([[0, d.token_ids[0][0]], [0, d.token_ids[1][0]]]), use_cache=True)
    for k in range(1, 4):
        step_logits, _, past = m.step(enc, emask, torch.tensor([[d.token_ids[0][k]], [d.token_ids[1][k]]]), past=past,
                                      use_cache=True)
        torch.testing.assert_close(step_logits[:, -1], full[:, k + 1], atol=1e-4, rtol=1e-4)
    # save / load: the folder records the encoder; no tokenizer is written or needed
    m.save(tmp_path / "t5", meta={"vae": "none"})
    import json

    info = json.loads((tmp_path / "t5" / "shapemove.json").read_text())
    from shapemove.core.models.text_encoder import fingerprint

    assert info["encoder"] == "minilm" and info["text_encoder"] == fingerprint() and info["num_codes"] == 1000
    again, reader = ShapeMoveT5.load(tmp_path / "t5")
    assert reader is minilm
    d2 = decode(again, again.inputs_for(reader, [p for p, _ in pairs], [s for _, s in pairs]), 1, 10, temperature=0)
    assert d2.codes == targets
    torch.testing.assert_close(d2.betas, d.betas, atol=1e-4, rtol=0)


def test_model_folder_with_another_encoder_or_tokenizer_is_refused(minilm, model, tok, tmp_path):
    import json

    m = ShapeMoveT5.build_minilm(1000, T5Size.tiny())
    m.save(tmp_path / "a")
    info = json.loads((tmp_path / "a" / "shapemove.json").read_text())
    info["text_encoder"]["sha256"] = "0" * 64
    (tmp_path / "a" / "shapemove.json").write_text(json.dumps(info))
    (tmp_path / "a" / "manifest.json").unlink(missing_ok=True)
    with pytest.raises(ShapeMoveError, match="trained with text encoder"):
        ShapeMoveT5.load(tmp_path / "a")
    # a T5 folder: its tokenizer must be there and be the one it was trained with
    model.save(tmp_path / "b", tok)
    (tmp_path / "b" / "manifest.json").unlink(missing_ok=True)
    other = tokenizer_from_sentencepiece(train_sentencepiece(TEXTS[:3] * 40, tmp_path / "sp2", vocab_size=80))
    other.save_pretrained(str(tmp_path / "b"))
    with pytest.raises(ShapeMoveError, match="not the tokenizer this model was trained with"):
        ShapeMoveT5.load(tmp_path / "b")
    (tmp_path / "b" / "tokenizer.json").unlink()
    with pytest.raises(ShapeMoveError, match="tokenizer"):
        ShapeMoveT5.load(tmp_path / "b")


def test_default_t5_reads_prompts_with_minilm():
    """The embedded default: MiniLM encoder, FSQ-sized code vocabulary, a decode of bounded length."""
    from shapemove.core.generation.model_bundle import DEFAULT_MODEL_DIR

    m, tok = ShapeMoveT5.load(DEFAULT_MODEL_DIR / "t5")
    assert m.encoder_kind == "minilm" and m.vocab.num_codes == 1000
    d = decode(m, m.inputs_for(tok, ["a person walks forward"], [None]), 4, 8, temperature=0)
    assert 4 <= len(d.codes[0]) <= 8 and d.betas.shape == (1, 10)


def test_sentence_token_reads_the_pooled_prompt_and_survives_save_load(tmp_path):
    """With ``sentence_token`` the memory gains one slot (the motion text's pooled, normalised MiniLM
    vector, projected); with ``text_dropout`` = 1 a training forward sees only that slot of the motion
    text, so two token sequences with the same mean give the same loss, while in eval mode (all tokens
    visible) they do not. The flag travels in config.json: a saved folder loads to the same logits."""
    from dataclasses import replace

    torch.manual_seed(0)
    size = replace(T5Size.tiny(), sentence_token=True, text_dropout=1.0)
    m = ShapeMoveT5.build_minilm(1000, size)
    B, L = 2, 5
    states = torch.randn(B, L, 384)
    mask = torch.ones(B, L, dtype=torch.bool)
    seg = torch.ones(B, L, dtype=torch.long)
    seg[:, :2] = 0  # two shape-text tokens first
    words = states[:, 2:]
    other = words - words.mean(1, keepdim=True) + words.mean(1, keepdim=True)  # same mean...
    other = other[:, [2, 0, 1]] * 1.0
    other[:, 0] += 0.5
    other[:, 1] -= 0.5  # ...different tokens
    states_b = torch.cat([states[:, :2], other], 1)
    assert torch.allclose(states_b[:, 2:].mean(1), words.mean(1), atol=1e-5)

    enc, emask = m.lm.eval().encode(states, mask, seg)
    assert enc.shape[1] == L + 1 and bool(emask[:, 0].all())
    pooled = torch.nn.functional.normalize(words.mean(1), dim=-1)
    expect = m.lm.sentence_proj(pooled) + m.lm.segment.weight[1]
    assert torch.allclose(enc[:, 0], expect, atol=1e-5)

    labels = torch.tensor([[m.vocab.beta_id, m.vocab.som_id, *m.vocab.codes_to_ids([3]), m.vocab.eom_id]] * B)
    m.train()
    loss_a = m(states, mask, labels, segments=seg)["ce"]
    loss_b = m(states_b, mask, labels, segments=seg)["ce"]
    assert torch.allclose(loss_a, loss_b, atol=1e-5)
    m.eval()
    with torch.no_grad():
        ea = m(states, mask, labels, segments=seg)["ce"]
        eb = m(states_b, mask, labels, segments=seg)["ce"]
    assert abs(float(ea - eb)) > 1e-4

    m.save(tmp_path / "t5")
    back = ShapeMoveT5.load(tmp_path / "t5")[0].eval()
    assert back.lm.config.sentence_token and back.lm.config.text_dropout == 1.0
    with torch.no_grad():
        assert torch.allclose(back(states, mask, labels, segments=seg)["ce"], ea, atol=1e-5)
