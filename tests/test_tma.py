"""TMA: training (loss, retrieval of its training pairs, exact resume), loading, and text search
over a motion library (ranking, index cache, bad input). Real clips from the ``tiny_dataset``."""
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.eval.tma_embed import embed_motions, load_tma, real_motion_scores, text_inputs
from shapemove.core.models.tma import TMA
from shapemove.core.search.motion_search import INDEX_NAME, index_library, search
from shapemove.core.train.checkpoint import make_metadata, save_checkpoint
from shapemove.core.train.motion_dataset import load_stats
from shapemove.core.train.train_tma import TMAClips, TMATrainConfig, caption_key, train_tma

STEPS = 60
# training clips whose captions differ strongly (kick / jog in a circle / wave / run / walk)
LIBRARY = ["HDM_bd_kickLFront1Reps_001_120", "HDM_bk_jogLeftCircle4StepsRstart_003_120",
           "dataset-2_wave-left-hand_elderly_001", "dataset-1_run_happy_001", "cmu_02_01"]


pytestmark = pytest.mark.usefixtures("one_thread")


@pytest.fixture(scope="module")
def trained(tiny_dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("tma_run")
    metrics = train_tma(tiny_dataset, out, "tiny", steps=STEPS, verbose=False)
    return out, metrics


def test_loss_falls_and_training_pairs_are_retrieved(tiny_dataset, trained):
    out, metrics = trained
    assert metrics["step"] == STEPS and (out / "tma.pt").is_file()
    model, tok, mean, std = load_tma(out / "tma.pt")
    m_ref, s_ref = load_stats(tiny_dataset)
    np.testing.assert_array_equal(mean, m_ref)
    np.testing.assert_array_equal(std, s_ref)
    # InfoNCE on one fixed training batch: the freshly initialised model vs the trained one
    c = TMATrainConfig.tiny()
    clips = TMAClips(tiny_dataset, "train", mean, std)
    texts, feats, lengths = clips.batch(c, 0)
    text = text_inputs(model, tok, texts)  # MiniLM token states + mask
    keys = [caption_key(t) for t in texts]
    torch.manual_seed(c.seed)
    fresh = TMA(model.cfg).eval()
    with torch.no_grad():
        before = float(fresh.loss(fresh.text(*text), fresh.motion(feats, lengths), keys))
        after = float(model.loss(model.text(*text), model.motion(feats, lengths), keys))
    assert before > 1.5  # ~ log(batch): chance
    assert after < 0.5 * before, (before, after)
    # the trained model retrieves its own training pairs far above chance (1 / number of clips)
    scores = real_motion_scores(tiny_dataset, "train", (model, tok, mean, std))
    n = scores["clips"]
    assert n == len(clips) >= 10
    assert scores["r_precision_top1"] >= 3.0 / n, scores
    assert scores["r_precision_top3"] >= scores["r_precision_top1"]
    # an untrained model does not (same protocol, same clips)
    chance = real_motion_scores(tiny_dataset, "train", (fresh, tok, mean, std))
    assert scores["matching_score"] < chance["matching_score"]


def test_embedding_does_not_depend_on_batch_padding(trained):
    model, tok, mean, std = load_tma(trained[0])
    rng = np.random.default_rng(0)
    feats = [mean + std * rng.standard_normal((n, 263)).astype(np.float32) for n in (37, 90, 150, 333)]
    together = embed_motions(model, feats, mean, std)
    alone = np.concatenate([embed_motions(model, [f], mean, std) for f in feats])
    np.testing.assert_allclose(together, alone, atol=1e-5)
    np.testing.assert_allclose(np.linalg.norm(together, axis=1), 1.0, atol=1e-5)


def test_resume_equals_uninterrupted(tiny_dataset, tmp_path):
    c = TMATrainConfig.tiny()
    c.steps, c.batch_size, c.ckpt_every, c.model["max_frames"] = 8, 4, 100, 64
    train_tma(tiny_dataset, tmp_path / "full", c, verbose=False)
    calls = []

    def cancel():  # checked before each step: stop after 3 steps
        calls.append(1)
        return len(calls) > 3

    m = train_tma(tiny_dataset, tmp_path / "cut", c, cancel=cancel, verbose=False)
    assert m["step"] == 3 and not (tmp_path / "cut" / "tma.pt").exists()
    m = train_tma(tiny_dataset, tmp_path / "cut", c, resume=True, verbose=False)
    assert m["step"] == 8
    a = torch.load(tmp_path / "full" / "tma.pt", weights_only=True)["model"]
    b = torch.load(tmp_path / "cut" / "tma.pt", weights_only=True)["model"]
    assert a.keys() == b.keys()
    for k in a:
        assert torch.equal(a[k], b[k]), k
    # a different configuration cannot resume that run
    c.lr *= 2
    with pytest.raises(ShapeMoveError, match="lr"):
        train_tma(tiny_dataset, tmp_path / "cut", c, resume=True, verbose=False)


def test_checkpoint_of_another_kind_is_refused(trained, tmp_path):
    meta = make_metadata("savae", {"x": 1}, "openbody", np.zeros(263), np.ones(263))
    save_checkpoint(tmp_path / "tma.pt", {"model": {}}, meta)
    with pytest.raises(ShapeMoveError, match="'savae' checkpoint, expected 'tma'"):
        load_tma(tmp_path / "tma.pt")
    (tmp_path / "junk").mkdir()
    (tmp_path / "junk" / "tma.pt").write_bytes(b"not a checkpoint")
    with pytest.raises(ShapeMoveError, match="cannot read checkpoint"):
        load_tma(tmp_path / "junk")
    (tmp_path / "nothing").mkdir()
    with pytest.raises(ShapeMoveError, match="no tma.pt"):
        load_tma(tmp_path / "nothing")


def _library(tiny_dataset, folder: Path) -> Path:
    folder.mkdir()
    for cid in LIBRARY:
        np.savez(folder / f"{cid}.npz", features=np.load(tiny_dataset / "new_joint_vecs" / f"{cid}.npy"))
        (folder / f"{cid}.txt").write_text((tiny_dataset / "texts" / f"{cid}.txt").read_text())
    return folder


def test_search_ranks_the_captioned_clip_first(tiny_dataset, trained, tmp_path, mocap_root):
    lib = _library(tiny_dataset, tmp_path / "lib")
    bvh = next(Path(mocap_root, "bandai").rglob("dataset-1_kick_normal_001.bvh"))
    shutil.copy(bvh, lib / "sub_kick.bvh")  # a mocap file is converted on the fly
    index = index_library(lib, trained[0] / "tma.pt")
    assert sorted(index.ids) == sorted(LIBRARY + ["sub_kick"]) and not index.skipped
    for cid in LIBRARY:
        query = (tiny_dataset / "texts" / f"{cid}.txt").read_text().splitlines()[0]
        results = search(index, query, top_k=3)
        assert results[0][0] == cid, (query, results)
        assert results[0][1] >= results[1][1] >= results[2][1]
        assert results[0][3] == query and Path(results[0][2]).name == f"{cid}.npz"
    # a built dataset folder is a library too (every split)
    ds = index_library(tiny_dataset, trained[0] / "tma.pt", use_cache=False)
    assert len(ds) == len(list((tiny_dataset / "new_joint_vecs").glob("*.npy")))


def test_index_cache_is_reused_and_invalidated(tiny_dataset, trained, tmp_path):
    lib = _library(tiny_dataset, tmp_path / "lib")
    tma = load_tma(trained[0])
    first = index_library(lib, trained[0])
    assert not first.from_cache and (lib / INDEX_NAME).is_file()
    again = index_library(lib, trained[0])
    assert again.from_cache and again.ids == first.ids
    np.testing.assert_array_equal(again.embeddings, first.embeddings)
    # the cached embeddings are what the model gives
    f = np.load(lib / f"{LIBRARY[2]}.npz")["features"]
    np.testing.assert_allclose(again.embeddings[again.ids.index(LIBRARY[2])], embed_motions(tma[0], [f], tma[2], tma[3])[0], atol=1e-5)
    # a changed file rebuilds the index, with that motion's new embedding
    np.savez(lib / f"{LIBRARY[2]}.npz", features=f[:60])
    changed = index_library(lib, trained[0])
    assert not changed.from_cache
    i = changed.ids.index(LIBRARY[2])
    assert not np.allclose(changed.embeddings[i], first.embeddings[i], atol=1e-4)
    np.testing.assert_allclose(changed.embeddings[i], embed_motions(tma[0], [f[:60]], tma[2], tma[3])[0], atol=1e-5)
    # a removed file too
    (lib / f"{LIBRARY[0]}.npz").unlink()
    fewer = index_library(lib, trained[0])
    assert not fewer.from_cache and LIBRARY[0] not in fewer.ids


def test_bad_library_and_query(tiny_dataset, trained, tmp_path):
    tma = trained[0]
    with pytest.raises(ShapeMoveError, match="not found"):
        index_library(tmp_path / "missing", tma)
    (tmp_path / "empty").mkdir()
    with pytest.raises(ShapeMoveError, match="no motions found"):
        index_library(tmp_path / "empty", tma)
    (tmp_path / "bad").mkdir()
    np.savez(tmp_path / "bad" / "x.npz", features=np.zeros((30, 100), np.float32))
    with pytest.raises(ShapeMoveError, match="none of the 1 motion files"):
        index_library(tmp_path / "bad", tma)
    index = index_library(_library(tiny_dataset, tmp_path / "lib"), tma)
    for q in ("", "   "):
        with pytest.raises(ShapeMoveError, match="query is empty"):
            search(index, q)
    with pytest.raises(ShapeMoveError, match="top_k"):
        search(index, "a person walks", 0)
    with pytest.raises(ShapeMoveError, match="dataset folder not found"):
        train_tma(tmp_path / "missing", tmp_path / "run", "tiny", verbose=False)
    with pytest.raises(ShapeMoveError, match="TMA config"):
        TMATrainConfig.load("huge")


def test_cli_search_and_train_resume(tiny_dataset, trained, tmp_path, capsys):
    from shapemove.cli import main

    lib = _library(tiny_dataset, tmp_path / "lib")
    query = (tiny_dataset / "texts" / f"{LIBRARY[0]}.txt").read_text().splitlines()[0]
    assert main(["search", "--library", str(lib), "--query", query, "--top", "2", "--tma", str(trained[0])]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "rank" in lines[1] and lines[2].split()[2] == LIBRARY[0] and len(lines) == 4
    assert main(["search", "--library", str(tmp_path / "nope"), "--query", "walk", "--tma", str(trained[0])]) == 2
    assert "not found" in capsys.readouterr().err
    # `train tma --resume` on a finished run: reads the CLI arguments, loads last.pt, writes tma.pt again
    run = tmp_path / "run"
    shutil.copytree(trained[0], run)
    (run / "tma.pt").unlink()
    assert main(["train", "tma", "--data", str(tiny_dataset), "--out", str(run), "--config", "tiny",
                 "--steps", str(STEPS), "--resume", "--quiet"]) == 0
    a = torch.load(trained[0] / "tma.pt", weights_only=True)["model"]
    b = torch.load(run / "tma.pt", weights_only=True)["model"]
    assert all(torch.equal(a[k], b[k]) for k in a)


def test_tma_records_its_text_encoder_and_refuses_another(trained, tmp_path):
    from shapemove.core.models.text_encoder import fingerprint

    ckpt = torch.load(trained[0] / "tma.pt", weights_only=True)
    assert ckpt["metadata"]["text_encoder"] == fingerprint()
    assert ckpt["metadata"]["config"]["model"]["text_encoder"] == "minilm"
    ckpt["metadata"]["text_encoder"] = {**fingerprint(), "sha256": "f" * 64}
    torch.save(ckpt, tmp_path / "tma.pt")
    with pytest.raises(ShapeMoveError, match="trained with text encoder"):
        load_tma(tmp_path / "tma.pt")


def test_default_tma_embeds_with_minilm():
    """The embedded default TMA reads text through MiniLM: unit vectors, paraphrases closer than
    unrelated actions."""
    from shapemove.core.generation.model_bundle import DEFAULT_MODEL_DIR

    model, tok, mean, std = load_tma(DEFAULT_MODEL_DIR / "tma")
    assert model.cfg.text_encoder == "minilm"
    from shapemove.core.eval.tma_embed import embed_texts

    v = embed_texts(model, tok, ["a person walks forward", "someone walks ahead", "a person does a backflip"])
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), 1.0, atol=1e-5)
    assert v[0] @ v[1] > v[0] @ v[2]
