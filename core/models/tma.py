"""TMA: a contrastive text-motion alignment model (Human TOMATO's evaluator), used for
R-precision / matching score / FID and to search a motion library by text.

Text (``text_encoder="minilm"``, the default): the frozen pretrained MiniLM's token states (as TMR
reads a frozen language model) -> linear to ``dim`` -> small trained Transformer -> mean pool ->
unit vector. ``"sentencepiece"`` (models trained before MiniLM): the ShapeMove sentencepiece tokens
-> embedding -> small Transformer -> mean pool -> unit vector.
Motion: normalised 263-dim features -> 1D conv stem (4x down) -> Transformer -> mean pool -> unit
vector. Trained with a symmetric InfoNCE loss where captions that are identical are not treated
as negatives of each other (the same sentence often describes several clips).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import torch
import torch.nn.functional as F
from torch import nn


@dataclass
class TMAConfig:
    vocab_size: int = 2000
    dim: int = 256
    layers: int = 3
    heads: int = 4
    embed: int = 256
    feature_dim: int = 263
    max_text: int = 64
    max_frames: int = 200
    temperature: float = 0.07
    text_encoder: str = "minilm"  # or "sentencepiece" (old checkpoints; vocab_size then counts its pieces)

    @classmethod
    def tiny(cls, vocab_size: int) -> "TMAConfig":
        return cls(vocab_size=vocab_size, dim=64, layers=1, heads=2, embed=64)


def _sinusoid(n: int, d: int) -> torch.Tensor:
    pos = torch.arange(n)[:, None]
    div = torch.exp(torch.arange(0, d, 2) * (-math.log(10000.0) / d))
    pe = torch.zeros(n, d)
    pe[:, 0::2] = torch.sin(pos * div)
    pe[:, 1::2] = torch.cos(pos * div)
    return pe


def _pool(x: torch.Tensor, keep: torch.Tensor) -> torch.Tensor:
    keep = keep.float()[..., None]
    return (x * keep).sum(1) / keep.sum(1).clamp_min(1.0)


class TextEncoder(nn.Module):
    def __init__(self, cfg: TMAConfig):
        super().__init__()
        self.embed = nn.Embedding(cfg.vocab_size, cfg.dim, padding_idx=0)
        self.register_buffer("pos", _sinusoid(cfg.max_text, cfg.dim), persistent=False)
        layer = nn.TransformerEncoderLayer(cfg.dim, cfg.heads, cfg.dim * 2, dropout=0.1, batch_first=True)
        self.encoder = nn.TransformerEncoder(layer, cfg.layers, enable_nested_tensor=False)
        self.out = nn.Linear(cfg.dim, cfg.embed)
        self.max_text = cfg.max_text

    def forward(self, ids: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        ids, mask = ids[:, : self.max_text], mask[:, : self.max_text].bool()
        x = self.embed(ids) + self.pos[: ids.shape[1]]
        x = self.encoder(x, src_key_padding_mask=~mask)
        return F.normalize(self.out(_pool(x, mask)), dim=-1)


class StateTextEncoder(nn.Module):
    """Trained layers on top of a frozen pretrained encoder's token states (B, L, in_dim)."""

    def __init__(self, cfg: TMAConfig, in_dim: int = 384):
        super().__init__()
        self.proj = nn.Sequential(nn.Linear(in_dim, cfg.dim), nn.LayerNorm(cfg.dim))
        layer = nn.TransformerEncoderLayer(cfg.dim, cfg.heads, cfg.dim * 2, dropout=0.1, batch_first=True)
        self.encoder = nn.TransformerEncoder(layer, cfg.layers, enable_nested_tensor=False)
        self.out = nn.Linear(cfg.dim, cfg.embed)
        self.max_text = cfg.max_text

    def forward(self, states: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        states, mask = states[:, : self.max_text], mask[:, : self.max_text].bool()
        x = self.encoder(self.proj(states), src_key_padding_mask=~mask)
        return F.normalize(self.out(_pool(x, mask)), dim=-1)


class MotionEncoder(nn.Module):
    def __init__(self, cfg: TMAConfig):
        super().__init__()
        d = cfg.dim
        self.stem = nn.Sequential(nn.Conv1d(cfg.feature_dim, d, 3, padding=1), nn.GELU(),
                                  nn.Conv1d(d, d, 4, stride=2, padding=1), nn.GELU(),
                                  nn.Conv1d(d, d, 4, stride=2, padding=1))
        self.register_buffer("pos", _sinusoid(cfg.max_frames // 4 + 2, d), persistent=False)
        layer = nn.TransformerEncoderLayer(d, cfg.heads, d * 2, dropout=0.1, batch_first=True)
        self.encoder = nn.TransformerEncoder(layer, cfg.layers, enable_nested_tensor=False)
        self.out = nn.Linear(d, cfg.embed)
        self.max_frames = cfg.max_frames

    def forward(self, feats: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
        """feats (B,T,263) normalised, zero-padded; lengths (B,) valid frames."""
        feats = feats[:, : self.max_frames]
        lengths = lengths.to(feats.device).clamp(max=self.max_frames)
        x = F.pad(feats, (0, 0, 0, -feats.shape[1] % 4)).transpose(1, 2)  # whole 4-frame steps
        # padding is zeroed after every layer, so an embedding does not depend on the batch's padding
        valid = lengths
        for layer in self.stem:
            if isinstance(layer, nn.Conv1d) and layer.stride[0] == 2 and layer is not self.stem[-1]:
                valid = (valid + 1) // 2
            x = layer(x)
            if isinstance(layer, nn.GELU):
                x = x * (torch.arange(x.shape[-1], device=x.device)[None] < valid[:, None])[:, None]
        x = x.transpose(1, 2)
        n = x.shape[1]
        keep = torch.arange(n, device=x.device)[None] < (lengths[:, None] + 3) // 4
        x = self.encoder(x + self.pos[:n], src_key_padding_mask=~keep)
        return F.normalize(self.out(_pool(x, keep)), dim=-1)


class TMA(nn.Module):
    def __init__(self, cfg: TMAConfig):
        super().__init__()
        self.cfg = cfg
        if cfg.text_encoder not in ("minilm", "sentencepiece"):
            raise ValueError(f"unknown TMA text encoder {cfg.text_encoder!r}")
        self.text = StateTextEncoder(cfg) if cfg.text_encoder == "minilm" else TextEncoder(cfg)
        self.motion = MotionEncoder(cfg)

    def loss(self, t: torch.Tensor, m: torch.Tensor, text_keys: list[str] | None = None) -> torch.Tensor:
        """Symmetric InfoNCE; pairs whose captions are identical are masked out as negatives."""
        logits = t @ m.T / self.cfg.temperature
        if text_keys is not None:
            same = torch.tensor([[a == b for b in text_keys] for a in text_keys], device=logits.device)
            same.fill_diagonal_(False)
            logits = logits.masked_fill(same, float("-inf"))
        target = torch.arange(t.shape[0], device=logits.device)
        return (F.cross_entropy(logits, target) + F.cross_entropy(logits.T, target)) / 2

    def config_dict(self) -> dict:
        return asdict(self.cfg)
