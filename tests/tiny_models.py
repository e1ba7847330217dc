"""A tiny but real model folder (SA-VAE + ShapeMove T5 + TMA) trained end to end on a dataset.

    from tiny_models import tiny_bundle          # session fixture: (model_dir, dataset_dir)
    bundle = build_tiny_bundle(data, out)        # or build one yourself

The folder has the layout of ``core/generation/model_bundle.py``: ``savae.pt``, ``t5/``,
``tma/tma.pt`` + ``tma/tokenizer/``. Training runs are kept under ``out/runs``. Built once per
test process (cached by output folder) whatever the number of test modules that import the fixture.
"""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

VAE_STEPS, T5_STEPS, TMA_STEPS = 30, 60, 60
_BUILT: dict = {}


def tiny_vae_config():
    """Width 16, one resblock, 32-frame crops (8 codes: ``decode_long`` needs chunks longer than its
    4-code overlap; the shorter HDM05/CMU clips of the tiny dataset are left out of VAE training)."""
    from shapemove.core.models.savae import SAVAEConfig, TrainSettings

    t = TrainSettings(steps=VAE_STEPS, batch_size=4, window=32, lr=3e-3, warmup_steps=2, log_every=10,
                      val_every=10_000, val_batches=1, ckpt_every=10_000)
    return SAVAEConfig(width=16, depth=1, shape_hidden=16, train=t)


def build_tiny_bundle(data, out, body=None) -> Path:
    """Train a tiny SA-VAE, T5 and TMA on the dataset folder ``data``; returns ``out/model``."""
    import torch

    from shapemove.core.train.train_t5 import T5TrainConfig, train_t5
    from shapemove.core.train.train_tma import train_tma
    from shapemove.core.train.train_vae import train_vae

    out = Path(out)
    key = str(out.resolve())
    if key in _BUILT:
        return _BUILT[key]
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        runs, model = out / "runs", out / "model"
        train_vae(data, runs / "vae", tiny_vae_config(), body=body, device="cpu", verbose=False)
        t5 = T5TrainConfig.tiny()
        t5.steps, t5.lr, t5.ckpt_every = T5_STEPS, 3e-3, 10_000
        train_t5(data, runs / "vae" / "savae.pt", runs / "t5", t5, device="cpu", verbose=False)
        train_tma(data, runs / "tma", "tiny", steps=TMA_STEPS, device="cpu", verbose=False)
        model.mkdir(parents=True, exist_ok=True)
        shutil.copy2(runs / "vae" / "savae.pt", model / "savae.pt")
        shutil.copytree(runs / "t5" / "t5", model / "t5")
        (model / "tma").mkdir()
        shutil.copy2(runs / "tma" / "tma.pt", model / "tma" / "tma.pt")
        if (runs / "tma" / "tokenizer").is_dir():  # TMAs on sentencepiece; MiniLM ones need none
            shutil.copytree(runs / "tma" / "tokenizer", model / "tma" / "tokenizer")
    finally:
        torch.set_num_threads(threads)
    _BUILT[key] = model
    return model


@pytest.fixture(scope="session")
def tiny_bundle(tiny_dataset, tmp_path_factory):
    """(model folder, dataset folder): tiny models trained on the ``tiny_dataset`` fixture."""
    out = tmp_path_factory.getbasetemp() / "tiny_bundle"
    return build_tiny_bundle(tiny_dataset, out), tiny_dataset
