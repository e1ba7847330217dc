"""Shape-aware motion decoder.

Input: codes (B, N, C) and a shape token (B, 1, S) (``ShapeEmbedding`` of the betas). The token
is prepended to the code sequence along time -> N + 1 steps; T2M-GPT-style upsampling convs turn
it into (N + 1) * 2**down_t frames and the frames of the token step are dropped, so the output is
(B, N * 2**down_t, out_dim) normalized shape-aware features.

S is the width of the time stream: if S == C the codes enter as they are; otherwise they are first
lifted to S by a per-step linear map (FSQ's post-quantization projection).
"""
from __future__ import annotations

import torch
from torch import nn

from ..errors import ShapeMoveError
from .conv_blocks import Resnet1D


class Decoder(nn.Module):
    def __init__(self, code_dim: int, token_dim: int, out_dim: int, width: int, depth: int, dilation_growth: int,
                 down_t: int):
        super().__init__()
        self.up = 2 ** down_t
        self.code_dim, self.token_dim = code_dim, token_dim
        self.lift = nn.Identity() if token_dim == code_dim else nn.Linear(code_dim, token_dim)
        layers = [nn.Conv1d(token_dim, width, 3, padding=1), nn.ReLU()]
        for _ in range(down_t):  # each doubles T
            layers += [Resnet1D(width, depth, dilation_growth), nn.Upsample(scale_factor=2, mode="nearest"),
                       nn.Conv1d(width, width, 3, padding=1)]
        layers += [nn.Conv1d(width, width, 3, padding=1), nn.ReLU(), nn.Conv1d(width, out_dim, 3, padding=1)]
        self.net = nn.Sequential(*layers)

    def forward(self, codes: torch.Tensor, token: torch.Tensor) -> torch.Tensor:
        if codes.dim() != 3 or codes.shape[-1] != self.code_dim:
            raise ShapeMoveError(f"decoder codes must be (B, N, {self.code_dim}), got {tuple(codes.shape)}")
        if token.shape != (codes.shape[0], 1, self.token_dim):
            raise ShapeMoveError(f"shape token must be (B, 1, {self.token_dim}), got {tuple(token.shape)}")
        stream = torch.cat([token, self.lift(codes)], dim=1)           # (B, N+1, S): concatenated along time
        out = self.net(stream.transpose(1, 2)).transpose(1, 2)        # (B, (N+1)*up, out_dim)
        return out[:, self.up:]                                       # drop the token step's frames
