"""Residual dilated 1D convolution blocks (T2M-GPT / Jukebox style). Tensors are (B, C, T)."""
from __future__ import annotations

from torch import nn


class ResConv1DBlock(nn.Module):
    """x + conv1x1(relu(conv3_dilated(relu(x)))): keeps (B, width, T)."""

    def __init__(self, width: int, dilation: int):
        super().__init__()
        self.block = nn.Sequential(
            nn.ReLU(),
            nn.Conv1d(width, width, 3, padding=dilation, dilation=dilation),
            nn.ReLU(),
            nn.Conv1d(width, width, 1),
        )

    def forward(self, x):
        return x + self.block(x)


class Resnet1D(nn.Sequential):
    """``depth`` residual blocks with dilations growth**d, largest first (T2M-GPT's
    reverse_dilation): the receptive field grows to 1 + 2 * sum(growth**d) steps."""

    def __init__(self, width: int, depth: int, dilation_growth: int):
        dilations = [dilation_growth ** d for d in range(depth)][::-1]
        super().__init__(*[ResConv1DBlock(width, d) for d in dilations])
