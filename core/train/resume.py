"""What a resumed training run restores from ``last.pt``: the weights, the optimiser and schedule
states, the step reached and the random streams (torch, Python, numpy, CUDA), so that a resumed run
draws the same batches as one that never stopped. One definition for the SA-VAE, T5 and TMA loops."""
from __future__ import annotations

import random

import numpy as np
import torch


def rng_state() -> dict:
    """The random streams of this process, as tensors/lists that ``save_checkpoint`` can store."""
    np_state = np.random.get_state()
    py = random.getstate()
    return {"torch": torch.get_rng_state(), "python": list(py[1]), "python_gauss": py[2],
            "numpy": torch.from_numpy(np_state[1].astype(np.int64)), "numpy_pos": int(np_state[2]),
            "numpy_gauss": [int(np_state[3]), float(np_state[4])],
            "cuda": torch.cuda.get_rng_state_all() if torch.cuda.is_available() else []}


def set_rng_state(s: dict) -> None:
    """RNG states are CPU byte tensors, also in a checkpoint loaded with ``map_location="cuda"``."""
    torch.set_rng_state(s["torch"].cpu())
    random.setstate((3, tuple(s["python"]), s["python_gauss"]))
    np.random.set_state(("MT19937", s["numpy"].cpu().numpy().astype(np.uint32), s["numpy_pos"], *s["numpy_gauss"]))
    if s["cuda"] and torch.cuda.is_available():
        torch.cuda.set_rng_state_all([t.cpu() for t in s["cuda"]])


def restore(ckpt: dict, model, optimizer, scheduler, weights_key: str = "model") -> int:
    """Load a loaded ``last.pt`` (``load_checkpoint``) into the run; returns its step. ``weights_key``:
    where the checkpoint holds ``model``'s weights."""
    model.load_state_dict(ckpt[weights_key])
    optimizer.load_state_dict(ckpt["optimizer"])
    scheduler.load_state_dict(ckpt["scheduler"])
    set_rng_state(ckpt["rng"])
    return int(ckpt["step"])
