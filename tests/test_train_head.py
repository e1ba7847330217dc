"""`train head` (core/train/train_head.py): a new [BETA] head that reads the shape words, trained on an
exported model with its T5 frozen; the head kinds (core/models/beta_head.py) and the differentiable
read-back it learns from (core/train/beta_head_refit.py)."""
import json
import shutil

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from tiny_models import tiny_bundle  # noqa: F401  (fixture)

pytestmark = pytest.mark.usefixtures("one_thread")


def test_a_model_saved_before_head_kinds_loads_its_mlp_and_gives_the_same_betas(tmp_path):
    """A model folder whose shapemove.json has no "beta_head" entry (every model before the text
    head, e.g. the default until 2026-11-26) loads the MLP head and reads betas exactly as before."""
    from safetensors.torch import load_file, save_file

    from shapemove.core.model_files import write_manifest
    from shapemove.core.models.beta_head import BetaHead
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    model_dir = tmp_path / "model"
    shutil.copytree("weights/default", model_dir)
    with torch.random.fork_rng():
        torch.manual_seed(0)
        mlp = BetaHead(128)
    save_file({k: v.contiguous() for k, v in mlp.state_dict().items()}, str(model_dir / "t5" / "beta_head.safetensors"))
    info = json.loads((model_dir / "t5" / "shapemove.json").read_text())
    info.pop("beta_head", None)
    info.pop("beta_head_training", None)
    (model_dir / "t5" / "shapemove.json").write_text(json.dumps(info))
    write_manifest(model_dir)
    with torch.no_grad():
        model, reader = ShapeMoveT5.load(model_dir / "t5")
        assert type(model.beta_head) is BetaHead and "beta_head" not in model.info
        inputs = model.inputs_for(reader, ["a person walks forward.", "a person jumps."], ["a tall man", None])
        h = model.beta_state(inputs)
        w = {k: v.float() for k, v in load_file(str(model_dir / "t5" / "beta_head.safetensors")).items()}
        gelu = torch.nn.functional.gelu
        x = gelu(h @ w["net.0.weight"].T + w["net.0.bias"])
        x = gelu(x @ w["net.2.weight"].T + w["net.2.bias"])
        want = x @ w["net.4.weight"].T + w["net.4.bias"]  # the MLP of the first head, written out
        got = model.predict_betas(inputs)
        assert torch.allclose(got, want, atol=1e-6)
        assert torch.equal(got, model.betas_at(h, inputs))
        assert float((got[0] - got[1]).abs().max()) > 1e-3  # the state differs between the prompts


def test_the_default_model_ships_the_text_head():
    from shapemove.core.models.beta_head import TextBetaHead
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    with torch.no_grad():
        model, reader = ShapeMoveT5.load("weights/default/t5")
        assert type(model.beta_head) is TextBetaHead and model.info["beta_head"]["kind"] == "text"
        inputs = model.inputs_for(reader, ["a person nods."] * 2, ["a heavy old man", "a slim young woman"])
        man, woman = model.predict_betas(inputs).numpy()
    from shapemove.core.body.load import load_body_model

    pmap = load_body_model(None).phenotype_map
    g = pmap.names.index("gender")
    assert pmap.from_betas(man)[g] < 0.25 < 0.75 < pmap.from_betas(woman)[g]


def test_head_kinds_are_recorded_and_rebuilt():
    from shapemove.core.models.beta_head import BetaHead, TextBetaHead, build_head

    assert type(build_head(None, 128)) is BetaHead
    head = TextBetaHead(64, hidden=32, width=32, queries=2, heads=2)
    again = build_head(json.loads(json.dumps(head.config())), 64)
    again.load_state_dict(head.state_dict())
    h, text = torch.randn(3, 64), torch.randn(3, 5, 384)
    mask = torch.tensor([[1, 1, 1, 0, 0], [1, 1, 1, 1, 1], [0, 0, 0, 0, 0]], dtype=torch.bool)
    assert torch.equal(head.eval()(h, text, mask), again.eval()(h, text, mask))
    # padding is never read; a row without words equals no text at all
    other = text.clone()
    other[0, 3:] = 99.0
    assert torch.allclose(head(h, other, mask)[0], head(h, text, mask)[0], atol=1e-5)
    assert torch.allclose(head(h, text, mask)[2], head(h[2:], None, None)[0], atol=1e-5)
    assert not torch.allclose(head(h, text, mask)[0], head(h, text, mask.roll(1, 0))[0], atol=1e-3)  # the words count
    for bad in ({"kind": "lstm"}, {"kind": "text", "width": 30, "heads": 4}, {"kind": "mlp", "d_model": 32},
                {"kind": "text", "colour": 3}, "text"):
        with pytest.raises(ShapeMoveError):
            build_head(bad, 64)


def test_a_head_that_writes_sliders_reads_back_exactly_those(openbody):
    from shapemove.core.models.beta_head import build_head

    cfg = {"kind": "text", "hidden": 32, "width": 32, "queries": 2, "heads": 2, "sliders": 6}
    torch.manual_seed(0)
    head = build_head(cfg, 64, openbody.phenotype_map)
    torch.nn.init.normal_(head.net[-1].weight, std=0.3)
    h, text, mask = torch.randn(4, 64), torch.randn(4, 3, 384), torch.ones(4, 3, dtype=torch.bool)
    with torch.no_grad():
        betas = head(h, text, mask)
        x = head.text_in(text) + head.position(torch.arange(3))[None]
        x = head.mix(torch.cat([head.none.expand(4, 1, -1), x], 1))
        pooled, _ = head.pool(head.queries[None].expand(4, -1, -1), x, x)
        out = head.net(torch.cat([h, pooled.reshape(4, -1)], 1))
    written = (head.slider_mid + out[:, :6] * head.slider_half).numpy()
    lo, hi = openbody.phenotype_map.ranges[:, 0], openbody.phenotype_map.ranges[:, 1]
    read = np.stack([openbody.phenotype_map.from_betas(b) for b in betas.numpy()])
    assert np.allclose(read, np.clip(written, lo, hi), atol=2e-3)  # age in years: float32
    assert np.ptp(read[:, 1]) > 1.0  # the sliders differ between the rows
    loaded = build_head(json.loads(json.dumps(head.config())), 64)  # the map comes back from the weights
    loaded.load_state_dict(head.state_dict())
    assert torch.equal(loaded(h, text, mask), head(h, text, mask))


def test_readback_is_the_eval_reading_and_differentiable(openbody):
    from shapemove.core.body.shape_from_measurements import fast_mass
    from shapemove.core.train.beta_head_refit import Readback

    r = Readback(openbody)
    b = torch.tensor(np.random.default_rng(1).normal(size=(8, 10)).clip(-2, 2), dtype=torch.float32,
                     requires_grad=True)
    p = r.sliders(b).detach().numpy()
    want = np.stack([openbody.phenotype_map.from_betas(x) for x in b.detach().numpy()])
    lo, hi = openbody.phenotype_map.ranges[:, 0], openbody.phenotype_map.ranges[:, 1]
    assert np.allclose(np.clip(p, lo, hi), want, atol=1e-3)  # from_betas clips; the loss reads it unclipped
    kg = r.mass(b)
    assert np.allclose(kg.detach().numpy(), fast_mass(openbody, b.detach().numpy()), rtol=1e-4)
    assert 30 < float(kg.detach().min()) and float(kg.detach().max()) < 200
    (kg.sum() + r.sliders(b)[:, 0].sum()).backward()
    assert b.grad.abs().sum() > 0


def test_stated_texts_state_the_body(openbody):
    from shapemove.core.body.shape_from_measurements import girth_regression, shape_words
    from shapemove.core.train.beta_head_refit import synthetic_bodies, synthetic_pool

    texts, betas, pheno = synthetic_pool(openbody, girth_regression(openbody), 5, 60, stated_share=1.0)
    from shapemove.core.body.shape_from_measurements import fast_measure

    m = fast_measure(openbody, betas.numpy(), ("height_cm", "mass_kg"))
    assert pheno.shape == (60, 6) and len(set(texts)) > 50
    read = 0
    for i, t in enumerate(texts):
        try:
            d = shape_words(t)
        except ShapeMoveError:  # the phenotype's build word against its BMI ("obese" at BMI 27): left out
            continue
        if d.height_cm is not None:  # feet and inches: whole inches
            assert abs(d.height_cm - m[i, 0]) <= 1.3, (t, m[i, 0])
            read += 1
        if d.mass_kg is not None:  # whole kg, lb or stones and lb
            assert abs(d.mass_kg - m[i, 1]) <= 0.8, (t, m[i, 1])
            read += 1
    assert read >= 50
    # the pool the T5's head phase draws is unchanged by the new options
    assert synthetic_bodies(openbody, girth_regression(openbody), 5, 6)[0] == synthetic_pool(
        openbody, girth_regression(openbody), 5, 6)[0]


def _decode(model_dir, prompts):
    from shapemove.core.models.constrained_decoding import decode
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    model, reader = ShapeMoveT5.load(model_dir / "t5")
    inputs = model.inputs_for(reader, prompts, ["a very tall heavy man", None])
    return model, inputs, decode(model, inputs, 2, 6, temperature=0.0)


def test_train_head_changes_only_the_head_and_resumes(tiny_bundle, tmp_path):
    from shapemove.core.train.train_head import HeadTrainConfig, train_head

    model_dir, data = tiny_bundle
    c = HeadTrainConfig.tiny()
    run = tmp_path / "run"
    res = train_head(model_dir, data, run, c, verbose=False)
    assert res["step"] == c.steps and "val" in res
    new = run / "model"
    changed = {"t5/beta_head.safetensors", "t5/shapemove.json"}  # and the manifest: one new one for the folder
    for f in model_dir.rglob("*"):
        rel = f.relative_to(model_dir).as_posix()
        if f.is_file() and rel not in changed and f.name != "manifest.json":
            assert (new / rel).read_bytes() == f.read_bytes(), rel  # the T5, SA-VAE, TMA: the same files
    prompts = ["a person walks forward.", "someone waves with the right hand."]
    before, _, dec0 = _decode(model_dir, prompts)
    after, inputs, dec1 = _decode(new, prompts)
    for k, v in before.lm.state_dict().items():
        assert torch.equal(v, after.lm.state_dict()[k]), k
    assert dec0.codes == dec1.codes and dec0.token_ids == dec1.token_ids  # motion tokens: bit-identical
    assert after.beta_head.kind == "text" and after.info["beta_head"]["width"] == 32
    assert after.info["beta_head"]["sliders"] == 6
    assert not torch.allclose(dec0.betas, dec1.betas)  # the new head gives the betas
    assert torch.allclose(dec1.betas, after.predict_betas(inputs), atol=1e-5)  # generation reads the words too

    # killed after 5 steps (checkpoints every 4), then resumed: the same head as the run that never stopped
    cut = tmp_path / "cut"
    calls = iter(range(100))
    train_head(model_dir, data, cut, c, verbose=False, cancel=lambda: next(calls) >= 5)
    assert not (cut / "model").exists()
    shutil.rmtree(cut / "model", ignore_errors=True)
    train_head(model_dir, data, cut, c, resume=True, verbose=False)
    from safetensors.torch import load_file

    a = load_file(str(new / "t5" / "beta_head.safetensors"))
    b = load_file(str(cut / "model" / "t5" / "beta_head.safetensors"))
    for k in a:
        assert torch.allclose(a[k], b[k], atol=1e-6), k
    c2 = HeadTrainConfig.tiny()
    c2.slider_weight = 5.0
    with pytest.raises(ShapeMoveError, match="slider_weight"):
        train_head(model_dir, data, cut, c2, resume=True, verbose=False)


def test_train_head_refuses_bad_input(tiny_bundle, tmp_path):
    from shapemove.core.train.run_guard import check_run_folder
    from shapemove.core.train.train_head import HeadTrainConfig, train_head

    model_dir, data = tiny_bundle
    c = HeadTrainConfig.tiny()
    with pytest.raises(ShapeMoveError, match="model folder not found"):
        train_head(tmp_path / "nowhere", data, tmp_path / "r1", c, verbose=False)
    no_t5 = tmp_path / "no_t5"
    no_t5.mkdir()
    shutil.copy2(model_dir / "savae.pt", no_t5 / "savae.pt")
    with pytest.raises(ShapeMoveError, match="no t5/"):
        train_head(no_t5, data, tmp_path / "r2", c, verbose=False)
    with pytest.raises(ShapeMoveError, match="dataset folder not found"):
        train_head(model_dir, tmp_path / "no_data", tmp_path / "r3", c, verbose=False)
    with pytest.raises(ShapeMoveError, match="inside the source model"):
        train_head(model_dir, data, model_dir / "run", c, verbose=False)
    c.head = {"kind": "lstm"}
    with pytest.raises(ShapeMoveError, match="head config"):
        train_head(model_dir, data, tmp_path / "r4", c, verbose=False)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"steps": 3, "colour": 1}))
    with pytest.raises(ShapeMoveError, match="unknown head config keys"):
        HeadTrainConfig.load(str(bad))
    done = tmp_path / "done"
    (done / "model").mkdir(parents=True)
    (done / "model" / "manifest.json").write_text("{}")
    with pytest.raises(ShapeMoveError, match="already holds a finished head"):
        check_run_folder(done, "head")


def test_cli_train_head_says_what_is_wrong(tmp_path, capsys):
    from shapemove.cli import main

    assert main(["train", "head", "--model", str(tmp_path / "none"), "--data", str(tmp_path), "--out",
                 str(tmp_path / "run"), "--quiet"]) == 2
    assert "model folder not found" in capsys.readouterr().err


def test_head_training_words_leave_the_evaluation_words_out():
    """The words the head's pool adds to phenotype_texts never include the evaluation's muscle words
    or the nouns of its own check phrases (tools/head_words_check.py): those measure how far the
    head carries over to words it never saw."""
    from shapemove.core.eval.shape_words_eval import MUSCLE_TEST_WORDS
    from shapemove.core.train.beta_head_refit import MORE_AGE, MORE_BUILD, MORE_NOUNS

    added = {w for group in (MORE_NOUNS, MORE_AGE, MORE_BUILD) for words in group.values() for w in words}
    assert not added & set(MUSCLE_TEST_WORDS), added & set(MUSCLE_TEST_WORDS)
    checked = {"grandmother", "powerlifter", "nurse", "linebacker", "lumberjack", "ballerina", "schoolgirl",
               "basketball player", "heavyweight boxer", "gymnast", "hulking", "burly", "frail", "stout"}
    assert not {w for w in added if any(c in w for c in checked)}


def test_the_pool_draws_teenagers_and_tall_women_when_asked(openbody):
    """``teen_share`` draws that share at 14-19 years (the map extrapolated below its 18, as the parser
    does for "teenage"); ``height_margin`` widens the height slider past its range, so tall women and
    short men are drawn. With neither, the draw is the dataset builder's, number for number."""
    from shapemove.core.body.phenotype_sample import TEEN_AGES, sample_phenotypes

    pmap = openbody.phenotype_map
    names = list(pmap.names)
    age, height = names.index("age"), names.index("height")
    plain = sample_phenotypes(pmap, np.random.default_rng(4), 4000)
    assert np.array_equal(plain, sample_phenotypes(pmap, np.random.default_rng(4), 4000, 0.0, 0.0))
    assert plain[:, age].min() >= 18.0 and (plain[:, age] < 20).mean() < 0.05
    wide = sample_phenotypes(pmap, np.random.default_rng(4), 4000, teen_share=0.25, height_margin=0.2)
    teen = wide[:, age] < TEEN_AGES[1]
    assert 0.24 < teen.mean() < 0.31   # 25 % drawn as teenagers + the 3 % of 18-19s of the uniform draw
    assert wide[:, age].min() >= TEEN_AGES[0] and (wide[:, age] < 18).mean() > 0.15
    lo, hi = pmap.ranges[height]
    span = 0.2 * (hi - lo)
    assert wide[:, height].min() >= lo - span and wide[:, height].max() <= hi + span
    assert (wide[:, height] > hi).mean() > 0.08 and (wide[:, height] < lo).mean() > 0.08


def test_stated_texts_say_an_age_with_any_noun():
    """A teenager is also "a teenage woman" or "a guy in his teens", not only "a girl" or "a boy", so the
    head learns the age words apart from the nouns that usually carry them."""
    from shapemove.core.data.phenotype_captions import decade_words
    from shapemove.core.train.beta_head_refit import stated_text

    assert [decade_words(a) for a in (14, 19.9, 20, 47, 72, 80, 95)] == [
        "teens", "teens", "twenties", "forties", "seventies", "eighties", "eighties"]
    teen = {"gender": 0.95, "age": 16.0, "muscle": 0.4, "weight": 0.4}
    texts = [stated_text(teen, {"height_cm": 160.0, "mass_kg": 52.0}, f"k{i}").lower() for i in range(400)]
    adult_nouns = ("woman", "lady", "mom", "aunt", "daughter", "girlfriend", "madam")
    said = [t for t in texts if any(w in t for w in ("teenage", "adolescent", "in her teens"))]
    assert any(any(n in t for n in adult_nouns) for t in said), said[:10]
    assert any("in her teens" in t for t in texts)
    assert not any(" he " in f" {t} " or "his " in t for t in texts)   # her, never his
    # and in years, in the forms the parser reads, the number its own: "16 years old", "aged 16"
    years = [t for t in texts if any(f in t for f in ("16 years old", "aged 16", "16 yo"))]
    assert 40 <= len(years) <= 200 and all("in her 10s" not in t for t in texts)
    adult = {**teen, "age": 47.0}
    assert any("in her 40s" in stated_text(adult, {"height_cm": 160.0}, f"k{i}") for i in range(200))


def test_a_head_that_meets_its_sizes_lands_the_mesh_on_them(openbody):
    """``meet`` moves betas along the height and weight sliders until the rest mesh measures the
    height and mass asked; checked with ``fast_measure`` (the mesh's top minus bottom vertex, its
    volume x density), not with the head's own arrays. Saved and loaded, the head meets them the same."""
    from shapemove.core.body.shape_from_measurements import fast_measure
    from shapemove.core.models.beta_head import build_head
    from shapemove.core.train.beta_head_refit import Readback

    config = {"kind": "text", "hidden": 32, "width": 32, "queries": 2, "heads": 2, "sliders": 6, "numbers": 6,
              "meets": 1}
    torch.manual_seed(0)
    head = build_head(config, 16, openbody.phenotype_map, Readback(openbody).size_model())
    start = torch.tensor(np.random.default_rng(0).normal(size=(5, 10)).clip(-1.5, 1.5), dtype=torch.float32)
    target = torch.tensor([[180.0, 80.0], [150.0, 45.0], [195.0, 120.0], [165.0, 60.0], [172.0, 95.0]])
    before = fast_measure(openbody, start.numpy(), ("height_cm", "mass_kg"))
    assert np.abs(before - target.numpy()).max() > 20
    met = head.meet(start, target)
    after = fast_measure(openbody, met.numpy(), ("height_cm", "mass_kg"))
    assert np.abs(after - target.numpy()).max() < 0.05
    # only the height and weight sliders moved: the others read back as before
    pmap = openbody.phenotype_map
    keep = [i for i, n in enumerate(pmap.names) if n not in ("height", "weight")]
    p0 = np.stack([np.linalg.lstsq(pmap.matrix.T, b - pmap.intercept, rcond=None)[0] for b in start.numpy()])
    p1 = np.stack([np.linalg.lstsq(pmap.matrix.T, b - pmap.intercept, rcond=None)[0] for b in met.numpy()])
    assert np.abs(p0[:, keep] - p1[:, keep]).max() < 1e-3
    loaded = build_head(head.config(), 16)
    loaded.load_state_dict(head.state_dict())
    assert torch.allclose(loaded.meet(start, target), met, atol=1e-4)
    h, text = torch.randn(2, 16), torch.randn(2, 4, 384)
    mask, numbers = torch.ones(2, 4, dtype=torch.bool), torch.zeros(2, 4, 6)
    with torch.no_grad():
        betas = loaded(h, text, mask, numbers)
        loaded.reading_sizes = True
        raw, said = loaded(h, text, mask, numbers)
    sizes = fast_measure(openbody, betas.numpy(), ("height_cm", "mass_kg"))
    assert np.abs(sizes - said.numpy()).max() < 0.05   # the body is the size the head read
    assert not torch.allclose(raw, betas)


def test_train_head_trains_a_head_that_reads_numbers_and_meets_them(tiny_bundle, tmp_path):
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5
    from shapemove.core.train.train_head import HeadTrainConfig, train_head

    model_dir, data = tiny_bundle
    c = HeadTrainConfig.tiny()
    c.head = {**c.head, "numbers": 6, "meets": 1}
    res = train_head(model_dir, data, tmp_path / "run", c, verbose=False)
    assert res["step"] == c.steps
    t5, reader = ShapeMoveT5.load(tmp_path / "run" / "model" / "t5")
    assert t5.info["beta_head"]["meets"] == 1 and t5.beta_head.reads_numbers
    betas = t5.predict_betas(t5.inputs_for(reader, ["a person walks."] * 2, ["a man, 180 cm, 80 kg", None]))
    assert betas.shape == (2, 10) and torch.isfinite(betas).all()


def test_a_pointing_head_leaves_a_body_described_in_words_alone(openbody):
    """meets 2: with no number in the text the body keeps its own size (``meet`` is a no-op); with a
    number pointed at, the mesh measures what it states."""
    from shapemove.core.body.shape_from_measurements import fast_measure
    from shapemove.core.models.beta_head import build_head
    from shapemove.core.train.beta_head_refit import Readback

    torch.manual_seed(1)
    head = build_head({"kind": "text", "hidden": 32, "width": 32, "queries": 2, "heads": 2, "sliders": 6,
                       "numbers": 6, "meets": 2}, 16, openbody.phenotype_map, Readback(openbody).size_model())
    h, text, mask = torch.randn(2, 16), torch.randn(2, 4, 384), torch.ones(2, 4, dtype=torch.bool)
    numbers = torch.zeros(2, 4, 6)
    numbers[1, 2] = torch.tensor([1.0, 0.0, 0.0, 1.80, 0.0, 0.0])   # "180" in the second text
    with torch.no_grad():
        head.pointer.weight.zero_()
        head.pointer.bias.copy_(torch.tensor([30.0, -30.0, 0.0, 0.0]))   # the number is a height in cm
        betas = head(h, text, mask, numbers)
        head.reading_sizes = True
        raw, said = head(h, text, mask, numbers)
    assert torch.allclose(betas[0], raw[0], atol=1e-4)          # words only: untouched
    sizes = fast_measure(openbody, betas.numpy(), ("height_cm", "mass_kg"))
    own = fast_measure(openbody, raw.numpy(), ("height_cm", "mass_kg"))
    assert abs(sizes[1, 0] - 180.0) < 0.05 and abs(sizes[1, 1] - own[1, 1]) < 0.05   # height met, mass kept
