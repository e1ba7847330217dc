"""Training speed: SA-VAE and T5 steps per second with the ``small`` configs (what `make
train-default` uses on a CPU), beside the ``tiny`` configs of the tests as the baseline, same run.

Each run trains a few steps from scratch on ``bench/inputs.small_dataset()`` (real clips) and
logs every step; the rate is 1 / the median step time after the first step (start-up and
first-touch costs excluded; the median resists the load of a shared machine). The T5 runs
tokenize the dataset with the small run's SA-VAE (not timed).
"""
from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

from .inputs import small_dataset


def _rate(log: Path) -> float:
    times = [json.loads(line)["sec_per_step"] for line in log.read_text().splitlines()]
    return 1.0 / float(np.median(times[1:] if len(times) > 1 else times))


def _vae(data: Path, out: Path, small: bool, steps: int) -> float:
    from ..core.models.savae import SAVAEConfig, TrainSettings
    from ..core.train.train_vae import train_vae

    if small:
        cfg = SAVAEConfig.small()
    else:  # the tests' tiny model (tests/tiny_models.py)
        cfg = SAVAEConfig(width=16, depth=1, shape_hidden=16, train=TrainSettings(batch_size=4, window=32))
    t = cfg.train
    t.steps, t.warmup_steps, t.log_every, t.val_every, t.ckpt_every = steps, 1, 1, 10**9, 10**9
    train_vae(data, out, cfg, device="cpu", verbose=False)
    return _rate(out / "log.jsonl")


def _t5(data: Path, vae: Path, out: Path, small: bool, steps: int) -> float:
    from ..core.train.train_t5 import T5TrainConfig, train_t5

    c = T5TrainConfig() if small else T5TrainConfig.tiny()
    c.steps, c.warmup_steps, c.log_every, c.ckpt_every = steps, 1, 1, 10**9
    train_t5(data, vae, out, c, device="cpu", verbose=False)
    return _rate(out / "log.jsonl")


def run(quick: bool = False) -> dict:
    import torch

    data = small_dataset()
    steps = 4 if quick else 12
    print(f"{steps} steps per run on {data} ({len((data / 'train.txt').read_text().split())} training clips), "
          f"{torch.get_num_threads()} torch threads")
    with tempfile.TemporaryDirectory(prefix="shapemove_bench_train_") as tmp:
        tmp = Path(tmp)
        vae_tiny = _vae(data, tmp / "vae_tiny", False, steps)
        vae = _vae(data, tmp / "vae_small", True, steps)
        t5_tiny = _t5(data, tmp / "vae_small" / "savae.pt", tmp / "t5_tiny", False, steps)
        t5 = _t5(data, tmp / "vae_small" / "savae.pt", tmp / "t5_small", True, steps)
    print(f"SA-VAE tiny (baseline):  {vae_tiny:7.3g} steps/s")
    print(f"SA-VAE small:            {vae:7.3g} steps/s  (batch 32 x 64 frames, width 128; {vae_tiny / vae:.0f}x slower)")
    print(f"T5 tiny (baseline):      {t5_tiny:7.3g} steps/s")
    print(f"T5 small:                {t5:7.3g} steps/s  (batch 32, d_model 256, 4+4 layers; {t5_tiny / t5:.0f}x slower)")
    return {"vae_steps_per_s": vae, "t5_steps_per_s": t5, "vae_tiny_steps_per_s": vae_tiny,
            "t5_tiny_steps_per_s": t5_tiny}
