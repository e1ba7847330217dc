"""Motion encoder: (B, T, 263) normalized canonical-body features -> (B, T / 2**down_t, C)
pre-quantization latents (C = number of FSQ channels). T must be a multiple of 2**down_t."""
from __future__ import annotations

import torch
from torch import nn

from ..errors import ShapeMoveError
from .conv_blocks import Resnet1D


class Encoder(nn.Module):
    def __init__(self, in_dim: int, code_dim: int, width: int, depth: int, dilation_growth: int, down_t: int):
        super().__init__()
        self.down = 2 ** down_t
        layers = [nn.Conv1d(in_dim, width, 3, padding=1), nn.ReLU()]
        for _ in range(down_t):  # each halves T: kernel 4, stride 2, padding 1
            layers += [nn.Conv1d(width, width, 4, stride=2, padding=1), Resnet1D(width, depth, dilation_growth)]
        layers.append(nn.Conv1d(width, code_dim, 3, padding=1))
        self.net = nn.Sequential(*layers)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        if x.dim() != 3 or x.shape[1] % self.down:
            raise ShapeMoveError(f"encoder input must be (B, T, D) with T a multiple of {self.down}, got {tuple(x.shape)}")
        return self.net(x.transpose(1, 2)).transpose(1, 2)
