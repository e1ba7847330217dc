"""Finite Scalar Quantization (Mentzer et al. 2023, "Finite Scalar Quantization: VQ-VAE Made Simple").

Each of the C = len(levels) channels is bounded with a scaled tanh and rounded to one of
``levels[c]`` integers (straight-through gradient). Codes are the rounded values divided by
``levels // 2``, so they lie in [-1, 1]. With levels [8,5,5,5] there are 8*5*5*5 = 1000 codes;
an index in [0, 1000) is the mixed-radix number of the per-channel integers.
"""
from __future__ import annotations

import math

import torch
from torch import nn

from ..constants import FSQ_LEVELS
from ..errors import ShapeMoveError


def round_ste(z: torch.Tensor) -> torch.Tensor:
    """Round in the forward pass, identity gradient in the backward pass."""
    return z + (torch.round(z) - z).detach()


class FSQ(nn.Module):
    """Quantizer over the last dimension. ``forward(z)`` -> (codes, indices) for z (..., C)."""

    def __init__(self, levels=FSQ_LEVELS, eps: float = 1e-3):
        super().__init__()
        levels = [int(x) for x in levels]
        if not levels or min(levels) < 2:
            raise ShapeMoveError(f"FSQ levels must be integers >= 2, got {levels}")
        self.levels_list = levels
        self.eps = eps
        lv = torch.tensor(levels, dtype=torch.float32)
        self.register_buffer("levels", lv, persistent=False)
        self.register_buffer("basis", torch.tensor([math.prod(levels[:i]) for i in range(len(levels))], dtype=torch.int64), persistent=False)
        self.register_buffer("half_width", torch.floor(lv / 2), persistent=False)
        half_l = (lv - 1) * (1 + eps) / 2
        offset = torch.where(lv % 2 == 0, 0.5, 0.0)
        self.register_buffer("half_l", half_l, persistent=False)
        self.register_buffer("offset", offset, persistent=False)
        self.register_buffer("shift", torch.atanh(offset / half_l), persistent=False)

    @property
    def dim(self) -> int:
        return len(self.levels_list)

    @property
    def codebook_size(self) -> int:
        return math.prod(self.levels_list)

    def bound(self, z: torch.Tensor) -> torch.Tensor:
        """(..., C) -> values in (-L/2 - offset, L/2 - offset) per channel: even levels get the
        half-level offset so rounding yields exactly L integers (-L/2 .. L/2-1)."""
        return torch.tanh(z + self.shift) * self.half_l - self.offset

    def quantize(self, z: torch.Tensor) -> torch.Tensor:
        """(..., C) unbounded -> codes (..., C) in [-1, 1] with a straight-through gradient."""
        return round_ste(self.bound(z)) / self.half_width

    def codes_to_indices(self, codes: torch.Tensor) -> torch.Tensor:
        """(..., C) codes -> (...) int64 indices in [0, codebook_size)."""
        if codes.shape[-1] != self.dim:
            raise ShapeMoveError(f"FSQ codes must have {self.dim} channels, got {codes.shape[-1]}")
        digits = torch.round(codes * self.half_width + self.half_width).long()
        return (digits * self.basis).sum(-1)

    def indices_to_codes(self, indices: torch.Tensor) -> torch.Tensor:
        """(...) int64 indices -> (..., C) float codes."""
        indices = torch.as_tensor(indices, device=self.basis.device).long()
        if indices.numel() and (int(indices.min()) < 0 or int(indices.max()) >= self.codebook_size):
            raise ShapeMoveError(f"FSQ index out of range [0, {self.codebook_size})")
        digits = (indices[..., None] // self.basis) % self.levels.long()
        return (digits.float() - self.half_width) / self.half_width

    def forward(self, z: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        codes = self.quantize(z)
        return codes, self.codes_to_indices(codes.detach())


def codebook_usage(indices: torch.Tensor, codebook_size: int) -> dict:
    """Usage statistics of a batch of indices: fraction of the codebook used and perplexity
    (exp of the entropy of the index histogram; = codebook_size when usage is uniform)."""
    counts = torch.bincount(indices.reshape(-1).long().cpu(), minlength=codebook_size).double()
    p = counts / counts.sum().clamp(min=1)
    entropy = -(p[p > 0] * p[p > 0].log()).sum()
    return {"used_fraction": float((counts > 0).double().mean()), "perplexity": float(entropy.exp()),
            "counts": counts}
