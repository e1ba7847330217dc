"""A motion's tokens, one integer per step of 4 frames, with or without the residual code.

The T5 writes base codes: FSQ indices in [0, K) (K = the base codebook, 1000). A codec with a
residual code (``savae.SAVAEConfig.residual_levels``) encodes a captured motion to a base index b
and a residual index r per step; the two travel as one token ``b + K * (r + 1)``, so a step
without a residual (what the T5 wrote) is its base index as before, and every list of tokens
(candidates, a Motion's ``tokens``, the motion memory) carries either kind or a mix.

    tokens = pack(base, residual, K)          # (N,) base, (N,) residual (-1: none)
    base, residual = unpack(tokens, K)
    base_of(tokens, K)                        # what the T5 reads (prefixes, retrieved clips)
    token_limit(K)                            # tokens lie in [0, K * (K + 1))
"""
from __future__ import annotations

import numpy as np
import torch

from ..errors import ShapeMoveError


def token_limit(codebook: int) -> int:
    """One past the largest token: a residual codebook is never larger than the base one
    (``SAVAEConfig.validate``)."""
    return codebook * (codebook + 1)


def pack(base, residual, codebook: int):
    """Base indices (N,) and residual indices (N,) (-1 where there is none) -> tokens (N,)."""
    if base.shape != residual.shape:
        raise ShapeMoveError(f"base and residual codes differ in shape: {tuple(base.shape)} and {tuple(residual.shape)}")
    return base + codebook * (residual + 1)


def unpack(tokens, codebook: int):
    """Tokens -> (base indices, residual indices with -1 where a step has no residual)."""
    if (tokens < 0).any():
        raise ShapeMoveError("motion tokens must be >= 0")
    return tokens % codebook, tokens // codebook - 1


def base_of(tokens, codebook: int):
    """The base codes of tokens (a list, an array or a tensor): what the T5 reads and writes."""
    if isinstance(tokens, (torch.Tensor, np.ndarray)):
        return tokens % codebook
    return [int(t) % codebook for t in tokens]
