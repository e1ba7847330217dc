"""The `[BETA]` projection: an MLP from the T5 decoder's last hidden state at the `[BETA]`
position to the 10 body-shape betas (the paper's shape head)."""
from __future__ import annotations

import torch
from torch import nn


class BetaHead(nn.Module):
    def __init__(self, d_model: int, num_betas: int = 10, hidden: int = 256):
        super().__init__()
        self.net = nn.Sequential(nn.Linear(d_model, hidden), nn.GELU(), nn.Linear(hidden, hidden), nn.GELU(),
                                 nn.Linear(hidden, num_betas))

    def forward(self, hidden_at_beta: torch.Tensor) -> torch.Tensor:
        """(B, d_model) -> (B, 10)"""
        return self.net(hidden_at_beta)
