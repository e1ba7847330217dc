"""The optimiser of the transformer trainers (T5, TMA, the ``[BETA]`` head): AdamW, a linear warm-up of
``warmup_steps``, then a cosine from the learning rate down to 10 % of it at ``steps``; the settings
they share. One definition for the three (the SA-VAE's schedule has step decay too: ``train_vae.py``)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import torch


@dataclass
class OptimizerSettings:
    """The fields of a trainer's config that this optimiser reads besides ``steps`` and ``lr``."""
    warmup_steps: int = 200
    weight_decay: float = 0.01
    grad_clip: float = 1.0


def lr_at(step: int, c) -> float:
    """Multiplier of ``c.lr`` at ``step`` (``c`` has ``steps`` and ``warmup_steps``): linear warm-up, then
    cosine down to 10 %. A float: numpy scalars would make a checkpoint's scheduler state unloadable."""
    if step < c.warmup_steps:
        return (step + 1) / c.warmup_steps
    p = min(1.0, (step - c.warmup_steps) / max(1, c.steps - c.warmup_steps))
    return float(0.1 + 0.9 * 0.5 * (1 + math.cos(math.pi * p)))


def adamw_warmup_cosine(params, c):
    """(AdamW over ``params`` at ``c.lr`` with ``c.weight_decay``, its ``lr_at`` schedule)."""
    optimizer = torch.optim.AdamW(params, lr=c.lr, weight_decay=c.weight_decay)
    return optimizer, torch.optim.lr_scheduler.LambdaLR(optimizer, lambda s: lr_at(s, c))
