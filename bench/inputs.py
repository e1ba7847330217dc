"""Inputs the generation and training benchmarks share, built once into ``.cache/bench``:

- ``small_dataset()``: a dataset folder built by the real builder from a few real clips
  (Bandai, HDM05, CMU; ``core.io.archive.mocap_root``), resumable like any build;
- ``model_dir()``: the embedded default model when it exists, else a tiny model folder
  (SA-VAE + T5 + TMA, the tests' sizes) trained on ``small_dataset()`` (about 15 s, cached).
"""
from __future__ import annotations

import shutil
from pathlib import Path

from ..core.data.build import build_dataset
from ..core.generation.model_bundle import DEFAULT_MODEL_DIR
from ..core.io.archive import default_cache_dir, mocap_root

CLIPS = [
    "dataset-1_walk_feminine_001", "dataset-1_run_happy_001", "dataset-2_wave-left-hand_elderly_001",
    "dataset-2_walk_masculine_003", "dataset-1_kick_normal_001", "dataset-2_run_elderly_001",
    "dataset-1_dash_active_001", "dataset-1_walk-back_active_001",
    "HDM_bd_kickLFront1Reps_001_120", "HDM_bk_jogLeftCircle4StepsRstart_003_120", "cmu_02_01", "cmu_13_10",
]


def cache_dir() -> Path:
    return default_cache_dir() / "bench"


def small_dataset() -> Path:
    out = cache_dir() / "data"
    if not (out / "Mean.npy").is_file() or len((out / "train.txt").read_text().split()) < 4:
        report = build_dataset([mocap_root()], out, only=CLIPS, augment_share=0.5, verbose=False)
        print(f"built the benchmark dataset in {out}: {report.summary().splitlines()[0]}")
    return out


def model_dir() -> tuple[Path, str]:
    """(model folder, description)."""
    if (DEFAULT_MODEL_DIR / "savae.pt").is_file() and (DEFAULT_MODEL_DIR / "t5").is_dir():
        return DEFAULT_MODEL_DIR, "the default model"
    out = cache_dir() / "tiny_model"
    if not (out / "t5" / "shapemove.json").is_file():
        _train_tiny(small_dataset(), out)
    return out, "a tiny model (the default model is not built)"


def _train_tiny(data: Path, out: Path) -> None:
    from ..core.models.savae import SAVAEConfig, TrainSettings
    from ..core.train.train_t5 import T5TrainConfig, train_t5
    from ..core.train.train_tma import train_tma
    from ..core.train.train_vae import train_vae

    print(f"training a tiny model into {out} (no default model)")
    runs = out.with_name(out.name + "_runs")
    t = TrainSettings(steps=30, batch_size=4, window=32, lr=3e-3, warmup_steps=2, val_every=10_000, ckpt_every=10_000)
    train_vae(data, runs / "vae", SAVAEConfig(width=16, depth=1, shape_hidden=16, train=t), device="cpu", verbose=False)
    c = T5TrainConfig.tiny()
    c.steps, c.lr, c.ckpt_every = 60, 3e-3, 10_000
    train_t5(data, runs / "vae" / "savae.pt", runs / "t5", c, device="cpu", verbose=False)
    train_tma(data, runs / "tma", "tiny", steps=60, device="cpu", verbose=False)
    tmp = out.with_name(out.name + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    (tmp / "tma").mkdir(parents=True)
    shutil.copy2(runs / "vae" / "savae.pt", tmp / "savae.pt")
    shutil.copytree(runs / "t5" / "t5", tmp / "t5")
    shutil.copy2(runs / "tma" / "tma.pt", tmp / "tma" / "tma.pt")
    if (runs / "tma" / "tokenizer").is_dir():  # sentencepiece TMAs only
        shutil.copytree(runs / "tma" / "tokenizer", tmp / "tma" / "tokenizer")
    shutil.rmtree(out, ignore_errors=True)
    tmp.rename(out)
