"""Shape injection: an MLP embedding of the 10 betas that becomes one extra time step of the
decoder's input (the SA-VAE concatenates it with the motion codes along time)."""
from __future__ import annotations

import torch
from torch import nn

from ..errors import ShapeMoveError


class ShapeEmbedding(nn.Module):
    """betas (B, num_betas) -> token (B, 1, out_dim)."""

    def __init__(self, num_betas: int, hidden: int, out_dim: int):
        super().__init__()
        self.num_betas = num_betas
        self.mlp = nn.Sequential(nn.Linear(num_betas, hidden), nn.SiLU(), nn.Linear(hidden, hidden), nn.SiLU(),
                                 nn.Linear(hidden, out_dim))

    def forward(self, betas: torch.Tensor) -> torch.Tensor:
        if betas.dim() != 2 or betas.shape[-1] != self.num_betas:
            raise ShapeMoveError(f"betas must be (B, {self.num_betas}), got {tuple(betas.shape)}")
        return self.mlp(betas)[:, None, :]
