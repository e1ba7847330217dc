"""The [BETA] head's measurement phase (core/train/beta_head_refit.py, T5 training step 4) and the
differentiable measurements it trains on."""
import shutil

import numpy as np
import pytest
import torch

from shapemove.core.body.load import load_body_model
from shapemove.core.body.shape_from_measurements import fast_measure, girth_regression, torch_measure
from shapemove.core.errors import ShapeMoveError


def test_torch_measure_matches_fast_measure_and_has_gradients():
    body = load_body_model(None)
    b = np.random.default_rng(0).normal(size=(16, 10)).clip(-3, 3)
    want = fast_measure(body, b, ("height_cm", "waist_cm", "hip_cm"), girth_regression(body))
    measure = torch_measure(body, ("height_cm", "waist_cm", "hip_cm"))
    bt = torch.tensor(b, dtype=torch.float32, requires_grad=True)
    got = measure(bt)
    assert np.allclose(got.detach().numpy(), want, atol=0.02)  # cm, float32 vs float64
    got[:, 0].sum().backward()
    assert bt.grad.abs().sum() > 0
    with pytest.raises(ShapeMoveError, match="no differentiable measure"):
        torch_measure(body, ("arm_length_cm",))


def test_lr_schedule_is_a_plain_float():
    from shapemove.core.train.train_t5 import T5TrainConfig
    from shapemove.core.train.warmup_cosine import lr_at

    c = T5TrainConfig(steps=100, warmup_steps=10)
    assert all(type(lr_at(s, c)) is float for s in (0, 9, 10, 50, 100, 150))  # numpy scalars break last.pt loading


def test_head_phase_trains_only_the_head_and_resumes(tiny_dataset, tmp_path):
    from tiny_models import build_tiny_bundle

    from shapemove.core.models.shapemove_t5 import ShapeMoveT5
    from shapemove.core.train.train_t5 import T5TrainConfig, train_t5

    bundle = build_tiny_bundle(tiny_dataset, tmp_path / "bundle")
    vae = bundle.parent / "runs" / "vae" / "savae.pt"
    c = T5TrainConfig.tiny()
    c.steps, c.warmup_steps, c.ckpt_every = 8, 2, 4  # past the warm-up: last.pt must still load
    main = tmp_path / "main"
    train_t5(tiny_dataset, vae, main, c, device="cpu", verbose=False)
    before, _ = ShapeMoveT5.load(main / "t5")

    c.head_steps, c.head_batch_size, c.head_lr, c.head_synthetic_share = 12, 16, 3e-3, 0.5
    whole = tmp_path / "whole"
    shutil.copytree(main, whole)
    train_t5(tiny_dataset, vae, whole, c, resume=True, device="cpu", verbose=False)
    after, _ = ShapeMoveT5.load(whole / "t5")
    assert after.info["step"] == 20
    for k, v in before.lm.state_dict().items():  # the T5 is frozen in the head phase
        assert torch.equal(v, after.lm.state_dict()[k]), k
    moved = [k for k, v in before.beta_head.state_dict().items() if not torch.equal(v, after.beta_head.state_dict()[k])]
    assert moved

    # killed in the middle of the head phase (cancel after 5 head steps), then resumed: same head
    cut = tmp_path / "cut"
    shutil.copytree(main, cut)
    calls = iter(range(100))
    train_t5(tiny_dataset, vae, cut, c, resume=True, device="cpu", verbose=False, cancel=lambda: next(calls) >= 5)
    assert not (cut / "t5" / "beta_head.safetensors").exists() or ShapeMoveT5.load(cut / "t5")[0].info["step"] == 8
    train_t5(tiny_dataset, vae, cut, c, resume=True, device="cpu", verbose=False)
    resumed, _ = ShapeMoveT5.load(cut / "t5")
    for k, v in after.beta_head.state_dict().items():
        assert torch.allclose(v, resumed.beta_head.state_dict()[k], atol=1e-6), k


def test_synthetic_bodies_are_new_measured_and_described():
    from shapemove.core.body.measure import measure
    from shapemove.core.data.shape_text import parse_shape_text
    from shapemove.core.train.beta_head_refit import synthetic_bodies

    body = load_body_model(None)
    shapes, betas = synthetic_bodies(body, girth_regression(body), 3, 12)
    assert len(shapes) == 12 and betas.shape == (12, 10)
    assert betas.abs().max() <= 2.5 and len({tuple(b.tolist()) for b in betas}) == 12
    m = measure(body, betas.numpy())
    stated = [(i, parse_shape_text(t)) for i, t in enumerate(shapes)]
    numeric = [(i, p) for i, p in stated if "height_cm" in p]
    assert numeric, shapes
    for i, p in numeric:  # each text states its own body's height (feet/inches: within half an inch)
        assert abs(p["height_cm"] - float(m["height_cm"][i])) <= 1.3, (shapes[i], float(m["height_cm"][i]))
    again = synthetic_bodies(body, girth_regression(body), 3, 12)
    assert again[0] == shapes and torch.equal(again[1], betas)  # the seed decides: a resumed run has the same pool


def test_a_run_saved_before_new_options_resumes_with_their_defaults(tiny_dataset, tmp_path):
    from tiny_models import build_tiny_bundle

    from shapemove.core.errors import ShapeMoveError
    from shapemove.core.train.checkpoint import load_checkpoint, save_checkpoint
    from shapemove.core.train.train_t5 import T5TrainConfig, train_t5

    bundle = build_tiny_bundle(tiny_dataset, tmp_path / "bundle")
    vae = bundle.parent / "runs" / "vae" / "savae.pt"
    c = T5TrainConfig.tiny()
    c.steps, c.ckpt_every = 6, 3
    run = tmp_path / "run"
    train_t5(tiny_dataset, vae, run, c, steps=3, device="cpu", verbose=False)
    ck = load_checkpoint(run / "last.pt", kind="shapemove-t5")
    del ck["config"]["null_share"]  # as written before that option existed
    save_checkpoint(run / "last.pt", ck, ck["metadata"])
    assert train_t5(tiny_dataset, vae, run, c, resume=True, steps=6, device="cpu", verbose=False)["step"] == 6
    c.null_share = 0.2  # a real change is still refused
    with pytest.raises(ShapeMoveError, match="null_share"):
        train_t5(tiny_dataset, vae, run, c, resume=True, steps=8, device="cpu", verbose=False)
