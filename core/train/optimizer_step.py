"""One optimisation step of a training loop: clear the gradients, backpropagate ``loss``, clip the
gradient norm of ``params`` to ``grad_clip`` (0 or None: no clipping), step the optimiser and the
learning-rate schedule. One definition for the SA-VAE and TMA loops."""
from __future__ import annotations

import torch


def optimizer_step(loss: torch.Tensor, optimizer, scheduler, params, grad_clip: float | None) -> None:
    optimizer.zero_grad(set_to_none=True)
    loss.backward()
    if grad_clip:
        torch.nn.utils.clip_grad_norm_(params, grad_clip)
    optimizer.step()
    scheduler.step()
