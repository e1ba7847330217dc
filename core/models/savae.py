"""The shape-aware VAE (SA-VAE, "Shape My Moves" stage 1) and its configuration.

encode: normalized features of the motion on the canonical body (betas = 0), (B, T, 263)
        -> FSQ codes (B, T/4, 4) and indices (B, T/4) in [0, 1000)
decode: codes + betas (B, 10) -> normalized SHAPE-AWARE features (B, T, 263)
Features are normalized with the dataset Mean/Std, kept in the model as buffers (``mean``,
``std``) so a checkpoint carries them.
"""
from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field

import torch
from torch import nn

from ..config_presets import PRESETS, load_config
from ..constants import FSQ_LEVELS
from ..errors import ShapeMoveError
from ..train.checkpoint import load_checkpoint
from .decoder import Decoder
from .encoder import Encoder
from .fsq import FSQ
from .shape_embedding import ShapeEmbedding


@dataclass
class LossWeights:
    recon: float = 1.0        # smooth L1 on normalized features
    vel: float = 0.5          # smooth L1 on their temporal differences
    bone: float = 1.0         # |bone length - target body's bone length| (m)
    floating: float = 0.5     # lowest foot joint above the target's, on contact frames (m)
    slide: float = 0.5        # horizontal foot speed while the target foot is in contact (m/frame)
    penetrate: float = 1.0    # depth of joints below y = 0 (m)
    dyn_stability: float = 0.0  # HUMOS dynamic stability: ZMP outside the contact feet (m); off by default
    root: float = 0.0         # root travel: trajectory distance (m) + root channels (vae_losses.root_travel_loss)


@dataclass
class TrainSettings:
    steps: int = 300_000
    batch_size: int = 256        # global batch (split over the processes)
    window: int = 64             # frames per random crop
    lr: float = 2e-4
    weight_decay: float = 0.0
    adam_betas: tuple = (0.9, 0.99)
    warmup_steps: int = 1000     # linear warm-up
    decay: str = "step"          # "step" (x gamma at each milestone) | "cosine" | "none"
    milestones: tuple = (2 / 3,)  # fractions of `steps` for step decay
    gamma: float = 0.05
    min_lr_ratio: float = 0.0    # cosine floor as a fraction of lr
    grad_clip: float = 0.0       # 0 = off
    val_every: int = 2000
    val_batches: int = 8
    ckpt_every: int = 1000
    log_every: int = 50
    seed: int = 0
    num_workers: int = 0
    init_from: str = ""          # start from this trained savae.pt (its weights and its Mean/Std)
    freeze: tuple = ()           # parts left as they are: "encoder", "quantizer", "shape_embedding", "decoder"


PARTS = ("encoder", "quantizer", "shape_embedding", "decoder")  # the SAVAE's sub-modules, by attribute name


@dataclass
class SAVAEConfig:
    feature_dim: int = 263
    num_betas: int = 10
    levels: tuple = FSQ_LEVELS
    width: int = 512
    depth: int = 3
    dilation_growth: int = 3
    down_t: int = 2
    shape_hidden: int = 256
    shape_token_dim: int = 0     # width of the decoder's time stream: 0 = `width`; len(levels) = raw codes
    loss: LossWeights = field(default_factory=LossWeights)
    train: TrainSettings = field(default_factory=TrainSettings)

    @classmethod
    def paper(cls) -> "SAVAEConfig":
        return cls()

    @classmethod
    def tiny(cls) -> "SAVAEConfig":
        """A smoke run: width 16, one resblock, 32-frame crops, 40 steps."""
        return cls(width=16, depth=1, shape_hidden=16,
                   train=TrainSettings(steps=40, batch_size=4, window=32, lr=3e-3, warmup_steps=2, log_every=10,
                                       val_every=10_000, val_batches=1, ckpt_every=10_000))

    @classmethod
    def small(cls) -> "SAVAEConfig":
        """CPU-sized: width 128, same depth/dilations/downsampling as the paper."""
        return cls(width=128, shape_hidden=128,
                   train=TrainSettings(steps=4000, batch_size=32, warmup_steps=200, val_every=500, ckpt_every=250))

    @property
    def token_dim(self) -> int:
        return self.shape_token_dim or self.width

    @property
    def downsample(self) -> int:
        return 2 ** self.down_t

    # -- (de)serialization ---------------------------------------------------------------------
    def to_dict(self) -> dict:
        return json.loads(json.dumps(dataclasses.asdict(self)))  # tuples -> lists, plain JSON types

    @classmethod
    def from_dict(cls, d: dict) -> "SAVAEConfig":
        d = dict(d)
        base = cls._presets().get(d.pop("base", "paper"))
        if base is None:
            raise ShapeMoveError(f"config 'base' must be one of {', '.join(PRESETS)}")
        cfg = base()
        sub = {"loss": LossWeights, "train": TrainSettings}
        for key, value in d.items():
            if not hasattr(cfg, key):
                raise ShapeMoveError(f"unknown SA-VAE config key: {key!r}")
            if key in sub:
                cur = getattr(cfg, key)
                for k, v in dict(value).items():
                    if not hasattr(cur, k):
                        raise ShapeMoveError(f"unknown SA-VAE config key: {key}.{k}")
                    setattr(cur, k, tuple(v) if isinstance(v, list) else v)
            else:
                setattr(cfg, key, tuple(value) if isinstance(value, list) else value)
        cfg.validate()
        return cfg

    @classmethod
    def _presets(cls) -> dict:
        return {"tiny": cls.tiny, "small": cls.small, "paper": cls.paper}

    @classmethod
    def load(cls, name_or_path: str | None) -> "SAVAEConfig":
        """A preset (``config_presets.PRESETS``; None = small) or a JSON file (optionally with
        "base": a preset name, default paper, + overrides)."""
        return load_config("SA-VAE", name_or_path, cls._presets(), lambda d, p: cls.from_dict(d))

    def validate(self) -> None:
        for name, value in vars(self.loss).items():
            if not value >= 0:
                raise ShapeMoveError(f"loss.{name} must be >= 0, got {value!r}")
        if self.train.window % self.downsample:
            raise ShapeMoveError(f"train.window must be a multiple of {self.downsample}")
        if self.train.decay not in ("step", "cosine", "none"):
            raise ShapeMoveError("train.decay must be 'step', 'cosine' or 'none'")
        unknown = [p for p in self.train.freeze if p not in PARTS]
        if unknown:
            raise ShapeMoveError(f"train.freeze: unknown part(s) {', '.join(map(repr, unknown))}; parts are {', '.join(PARTS)}")
        if self.train.freeze and not self.train.init_from:
            raise ShapeMoveError("train.freeze needs train.init_from: freezing untrained weights keeps them random")
        if set(self.train.freeze) >= {"encoder", "shape_embedding", "decoder"}:
            raise ShapeMoveError("train.freeze leaves nothing to train")


class SAVAE(nn.Module):
    def __init__(self, cfg: SAVAEConfig, mean=None, std=None):
        super().__init__()
        cfg.validate()
        self.cfg = cfg
        c = len(cfg.levels)
        self.encoder = Encoder(cfg.feature_dim, c, cfg.width, cfg.depth, cfg.dilation_growth, cfg.down_t)
        self.quantizer = FSQ(cfg.levels)
        self.shape_embedding = ShapeEmbedding(cfg.num_betas, cfg.shape_hidden, cfg.token_dim)
        self.decoder = Decoder(c, cfg.token_dim, cfg.feature_dim, cfg.width, cfg.depth, cfg.dilation_growth, cfg.down_t)
        self.register_buffer("mean", torch.zeros(cfg.feature_dim))
        self.register_buffer("std", torch.ones(cfg.feature_dim))
        if mean is not None:
            self.set_stats(mean, std)

    def set_stats(self, mean, std) -> None:
        mean = torch.as_tensor(mean, dtype=torch.float32).reshape(-1)
        std = torch.as_tensor(std, dtype=torch.float32).reshape(-1)
        if mean.numel() != self.cfg.feature_dim or std.numel() != self.cfg.feature_dim:
            raise ShapeMoveError(f"Mean/Std must have {self.cfg.feature_dim} values")
        self.mean.copy_(mean)
        self.std.copy_(std)

    def normalize(self, features: torch.Tensor) -> torch.Tensor:
        return (features - self.mean) / self.std

    def denormalize(self, x: torch.Tensor) -> torch.Tensor:
        return x * self.std + self.mean

    def encode(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Normalized canonical features (B, T, D) -> codes (B, T/4, C), indices (B, T/4)."""
        return self.quantizer(self.encoder(x))

    def decode(self, codes: torch.Tensor, betas: torch.Tensor) -> torch.Tensor:
        """Codes (B, N, C), betas (B, 10) -> normalized shape-aware features (B, 4N, D)."""
        return self.decoder(codes, self.shape_embedding(betas))

    def decode_indices(self, indices: torch.Tensor, betas: torch.Tensor) -> torch.Tensor:
        return self.decode(self.quantizer.indices_to_codes(indices), betas)

    def forward(self, x: torch.Tensor, betas: torch.Tensor) -> dict:
        codes, indices = self.encode(x)
        return {"recon": self.decode(codes, betas), "codes": codes, "indices": indices}

    @torch.no_grad()
    def decode_long(self, codes: torch.Tensor, betas: torch.Tensor, chunk: int | None = None, overlap: int = 4) -> torch.Tensor:
        """Decode a sequence longer than the training window: overlapping chunks of ``chunk`` codes
        (default window/4), each with its own shape token, cross-faded over ``overlap`` codes, so
        every frame sits as close to a shape token as in training."""
        chunk = chunk or self.cfg.train.window // self.cfg.downsample
        overlap = min(overlap, chunk // 2)  # short training windows give short chunks
        n, up = codes.shape[1], self.cfg.downsample
        if n <= chunk:
            return self.decode(codes, betas)
        if not 0 <= overlap < chunk:
            raise ShapeMoveError("decode_long: overlap must be in [0, chunk)")
        starts = list(range(0, n - chunk + 1, chunk - overlap))
        if starts[-1] + chunk < n:
            starts.append(n - chunk)
        out = codes.new_zeros(codes.shape[0], n * up, self.cfg.feature_dim)
        total = codes.new_zeros(n * up, 1)
        ramp = overlap * up
        for s in starts:
            w = codes.new_ones(chunk * up, 1)
            if ramp and s > 0:
                w[:ramp, 0] = torch.linspace(0, 1, ramp + 2)[1:-1]
            if ramp and s + chunk < n:
                w[-ramp:, 0] = torch.linspace(1, 0, ramp + 2)[1:-1]
            out[:, s * up:(s + chunk) * up] += self.decode(codes[:, s:s + chunk], betas) * w
            total[s * up:(s + chunk) * up] += w
        return out / total


def load_savae(path, body=None, device="cpu") -> SAVAE:
    """A trained SA-VAE from ``savae.pt`` or ``last.pt`` (eval mode). ``body``: a BodyModel or its
    name; when given, a checkpoint trained for another body model is a ShapeMoveError."""
    name = body if body is None or isinstance(body, str) else body.name
    ckpt = load_checkpoint(path, map_location=device, kind="savae", body=name)
    meta = ckpt["metadata"]
    model = SAVAE(SAVAEConfig.from_dict(meta["config"]))
    model.load_state_dict(ckpt["model"])
    model.metadata = meta
    return model.to(device).eval()
