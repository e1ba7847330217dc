"""Text-to-motion end to end on tiny real models: generation (lengths, constrained decoding, motion
file) and the `eval generate` protocol (generated vs the real-data ceiling). The models are trained
on the ``tiny_dataset`` fixture by ``tiny_models.tiny_bundle`` (about 10 s)."""
import json
import math

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.eval.generate_eval import KEYS, eval_generate, format_results, load_clips
from shapemove.core.eval.tma_embed import load_tma, real_motion_scores
from shapemove.core.models.tma import TMA
from tiny_models import tiny_bundle  # noqa: F401  (session fixture)

PROMPT = "a person walks forward"


pytestmark = pytest.mark.usefixtures("one_thread")


@pytest.fixture(scope="module")
def generator(tiny_bundle):
    from shapemove.core.generation.generate import Generator

    return Generator(tiny_bundle[0])


# -- generation ----------------------------------------------------------------------------------

def test_generate_command_writes_a_complete_motion_of_the_asked_length(tiny_bundle, tmp_path):
    from shapemove.cli import main
    from shapemove.core.scene.motion_file import load_motion

    model, _ = tiny_bundle
    for seconds, frames in ((2.0, 40), (0.6, 12)):
        out = tmp_path / f"m{seconds}.npz"
        assert main(["generate", "--prompt", PROMPT, "--shape-text", "a tall, heavy-set man", "--seconds", str(seconds),
                     "--model", str(model), "--out", str(out)]) == 0
        with np.load(out) as z:
            assert {"joints", "betas", "poses", "transl", "fps", "body_model", "prompt", "tokens", "features"} <= set(z.files)
        m = load_motion(out)
        assert m.num_frames == frames and m.fps == 20 and len(m.tokens) == frames // 4
        assert m.joints.shape == (frames, 22, 3) and m.poses.shape == (frames, 24, 3) and m.features.shape == (frames, 263)
        assert m.prompt == PROMPT and np.isfinite(m.features).all() and np.isfinite(m.betas).all()
    assert main(["generate", "--prompt", PROMPT, "--seconds", "99", "--model", str(model),
                 "--out", str(tmp_path / "x.npz")]) == 2                     # out of range: a one-line error
    assert not (tmp_path / "x.npz").exists()


def test_constrained_decoding_gives_only_motion_codes(generator):
    size = generator.vae.quantizer.codebook_size
    free = generator.generate(PROMPT, temperature=1.0, top_k=None, seed=3)     # the model picks the length
    assert 4 <= len(free.tokens) <= generator.max_codes
    for m in (free, generator.generate(PROMPT, seconds=3.0, seed=1)):
        assert m.tokens.min() >= 0 and m.tokens.max() < size
        assert m.num_frames == 4 * len(m.tokens)
    a = generator.generate(PROMPT, seconds=1.0, temperature=0, seed=0)        # greedy: the seed does not matter
    b = generator.generate(PROMPT, seconds=1.0, temperature=0, seed=9)
    np.testing.assert_array_equal(a.tokens, b.tokens)
    np.testing.assert_allclose(a.features, b.features)


def test_redecode_keeps_tokens_and_follows_the_body(generator):
    from shapemove.core.body.measure import measure

    m = generator.generate(PROMPT, seconds=2.0, seed=0)
    tall = np.zeros(10, np.float32)
    tall[0] = 2.0
    r = generator.redecode(m, tall)
    np.testing.assert_array_equal(r.tokens, m.tokens)
    np.testing.assert_array_equal(r.betas, tall)
    assert r.num_frames == m.num_frames and not np.allclose(r.features, m.features)
    h = measure(generator.body, tall)["height_cm"]
    assert abs(h - measure(generator.body, np.zeros(10))["height_cm"]) > 2                     # a different body


# -- evaluation ------------------------------------------------------------------------------------

def test_eval_generate_on_the_test_split(tiny_bundle, generator):
    model, data = tiny_bundle
    ids = (data / "test.txt").read_text().split()
    res = eval_generate(data, "test", generator=generator)
    assert set(res) == set(KEYS) | {"ground_truth"}
    gen, real = {k: res[k] for k in KEYS}, res["ground_truth"]
    for col in (gen, real):
        assert set(col) == set(KEYS)
        assert all(math.isfinite(v) for v in col.values()), col
        assert col["clips"] == len(ids) >= 2
        assert 0 <= col["r_precision_top1"] <= col["r_precision_top3"] <= 1
    assert real["height_err_cm"] == real["waist_err_cm"] == 0 and real["fid"] == pytest.approx(0, abs=1e-6)
    assert gen["fid"] > 0
    # the real column is the TMA protocol on the real clips with the same captions
    ref = real_motion_scores(data, "test", model / "tma")
    for k in ("r_precision_top1", "r_precision_top3", "matching_score"):
        assert real[k] == pytest.approx(ref[k], rel=1e-5)
    # height/waist errors are those of the generated bodies (same seeds -> same betas)
    from shapemove.core.body.measure import measure

    from shapemove.core.generation.generate import Request

    clips = load_clips(data, "test")
    pred = [generator.generate_batch([Request(c["caption"], c["shape_text"], seconds=len(c["features"]) / 20, seed=i,
                                              shape_from="head")])[0].betas
            for i, c in enumerate(clips)]
    mp, mt = measure(generator.body, np.stack(pred)), measure(generator.body, np.stack([c["betas"] for c in clips]))
    assert gen["height_err_cm"] == pytest.approx(np.abs(mp["height_cm"] - mt["height_cm"]).mean(), rel=1e-5)
    assert gen["waist_err_cm"] == pytest.approx(np.abs(mp["waist_cm"] - mt["waist_cm"]).mean(), rel=1e-5)
    table = format_results(res)
    assert "R-precision top 1" in table and f"({len(ids)} clips)" in table


def test_eval_generate_max_clips_and_bad_input(tiny_bundle, generator, tmp_path):
    model, data = tiny_bundle
    res = eval_generate(data, "train", generator=generator, max_clips=3, seed=1)
    assert res["clips"] == res["ground_truth"]["clips"] == 3
    with pytest.raises(ShapeMoveError, match="at least 2"):
        eval_generate(data, "train", generator=generator, max_clips=1)
    with pytest.raises(ShapeMoveError, match="split 'nope'"):
        eval_generate(data, "nope", generator=generator)
    with pytest.raises(ShapeMoveError, match="not found"):
        eval_generate(tmp_path / "missing", generator=generator)
    import shutil

    bare = tmp_path / "model"
    shutil.copytree(model, bare, ignore=shutil.ignore_patterns("tma"))
    with pytest.raises(ShapeMoveError, match="no tma"):
        eval_generate(data, "test", bare)


def test_tiny_tma_ranks_real_training_motions_above_chance(tiny_bundle):
    model, data = tiny_bundle
    tma = load_tma(model / "tma")
    scores = real_motion_scores(data, "train", tma)
    n = scores["clips"]
    assert n >= 10
    assert scores["r_precision_top1"] >= 3.0 / n, scores          # chance is 1/n
    assert scores["r_precision_top3"] >= 6.0 / n, scores          # chance is 3/n
    torch.manual_seed(0)
    fresh = TMA(tma[0].cfg).eval()
    assert scores["matching_score"] < real_motion_scores(data, "train", (fresh, *tma[1:]))["matching_score"]


def test_eval_generate_command(tiny_bundle, tmp_path, capsys):
    from shapemove.cli import main

    model, data = tiny_bundle
    out = tmp_path / "res.json"
    assert main(["eval", "generate", "--data", str(data), "--split", "test", "--model", str(model),
                 "--tma", str(model / "tma" / "tma.pt"), "--max-clips", "2", "--json", str(out)]) == 0
    res = json.loads(out.read_text())
    assert set(res) - {"ground_truth"} == set(res["ground_truth"]) == set(KEYS) and res["clips"] == 2
    assert "Text-to-motion evaluation" in capsys.readouterr().out


def test_body_shape_from_stated_measurements_or_the_beta_head(generator):
    from shapemove.core.body.measure import measure
    from shapemove.core.generation.generate import Request

    tall = generator.generate_batch([Request("a person walks", "A person standing 190 cm tall", seconds=1.2)])[0]
    assert tall.shape_source == "measurements"
    assert measure(generator.body, tall.betas)["height_cm"] == pytest.approx(190, abs=1.5)
    short = generator.generate_batch([Request("a person walks", "a short, slim woman", seconds=1.2)])[0]
    assert measure(generator.body, short.betas)["height_cm"] < measure(generator.body, tall.betas)["height_cm"] - 20
    head = generator.generate_batch([Request("a person walks", "A person standing 190 cm tall", seconds=1.2,
                                             shape_from="head")])[0]
    assert head.shape_source == "[BETA] head"
    free = generator.generate_batch([Request("a person walks", "someone with broad shoulders", seconds=1.2)])[0]
    assert free.shape_source == "[BETA] head"  # free text: no shape word or number the parser reads
    given = generator.generate_batch([Request("a person walks", "tall", betas=np.full(10, 0.5), seconds=1.2)])[0]
    assert given.shape_source == "given" and np.allclose(given.betas, 0.5)
