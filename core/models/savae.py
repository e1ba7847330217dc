"""The shape-aware VAE (SA-VAE, "Shape My Moves" stage 1) and its configuration.

encode: normalized features of the motion on the canonical body (betas = 0), (B, T, 263)
        -> FSQ codes (B, T/4, 4) and indices (B, T/4) in [0, 1000)
decode: codes + betas (B, 10) -> normalized SHAPE-AWARE features (B, T, 263)

A codec with ``residual_levels`` has a second, residual code (``encode_residual``: its own encoder
and FSQ, one more index per step; ``motion_codes.py`` packs the two in one token) and a residual
branch that decodes both: a decoder and shape embedding of its own (``residual_decoder``,
``residual_shape_embedding``). The base decoder is left as it was, so the base codes the T5 writes
decode exactly as before; a motion encoded by the codec (a retargeted take, a user's library)
decodes through the residual branch. Training drops the residual of ``residual_dropout`` of the
clips (the branch then reads base codes and a flag saying the residual is missing).
Features are normalized with the dataset Mean/Std, kept in the model as buffers (``mean``,
``std``) so a checkpoint carries them.
"""
from __future__ import annotations

import dataclasses
import json
import math
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
from .motion_codes import pack, unpack
from .shape_embedding import ShapeEmbedding


@dataclass
class LossWeights:
    recon: float = 1.0        # smooth L1 on normalized features
    recon_mse: float = 0.0    # squared error on normalized features: a rare, far-off pose counts in full
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
    action_balance: float = 0.0  # clip sampling weight 1 / (clips of its main action) ** this (1 = actions equally)
    active_windows: float = 0.0  # crop starts: 0 uniform; 1 in proportion to how much the pose moves in the crop
    min_frames: int = 0          # shortest clip trained on (0: ``window``); a shorter one than the window padded, masked
    resident: bool = False       # every training clip held in the device's memory, batches cut there (a GPU run)


PARTS = ("encoder", "quantizer", "shape_embedding", "decoder", "residual_encoder", "residual_decoder",
         "residual_shape_embedding")  # sub-modules, by attribute name
RESIDUAL_PARTS = PARTS[4:]


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
    decoder_width: int = 0       # channels of the base decoder: 0 = `width` (a wider one can be fitted to frozen codes)
    residual_levels: tuple = ()  # FSQ levels of a residual code beside the base one; () = none
    residual_dropout: float = 0.5  # training: share of clips the residual branch decodes from base codes
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
    def base_decoder_width(self) -> int:
        return self.decoder_width or self.width

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
        trainable = {"encoder", "shape_embedding", "decoder"} if self.trains_base else set(RESIDUAL_PARTS)
        if set(self.train.freeze) >= trainable:
            raise ShapeMoveError("train.freeze leaves nothing to train")
        if set(self.train.freeze) & set(RESIDUAL_PARTS) and not self.residual_levels:
            raise ShapeMoveError("train.freeze: the residual parts need residual_levels")
        if self.residual_levels and math.prod(self.residual_levels) > math.prod(self.levels):
            raise ShapeMoveError("residual_levels: the residual codebook may not be larger than the base one "
                                 f"({math.prod(self.levels)} codes), so a token holds both (motion_codes.py)")
        if not 0 <= self.train.action_balance <= 1:
            raise ShapeMoveError(f"train.action_balance must be in [0, 1], got {self.train.action_balance!r}")
        if not 0 <= self.train.min_frames <= self.train.window:
            raise ShapeMoveError(f"train.min_frames must be in [0, train.window], got {self.train.min_frames!r}")
        if not 0 <= self.train.active_windows <= 1:
            raise ShapeMoveError(f"train.active_windows must be in [0, 1], got {self.train.active_windows!r}")
        if self.decoder_width < 0:
            raise ShapeMoveError(f"decoder_width must be >= 0, got {self.decoder_width!r}")
        if not 0 <= self.residual_dropout <= 1:
            raise ShapeMoveError(f"residual_dropout must be in [0, 1], got {self.residual_dropout!r}")

    @property
    def trains_base(self) -> bool:
        """Whether training decodes through the base path. A residual codec trains its residual
        branch (the base decoder is not in that forward pass) unless every residual part is frozen:
        then its base decoder is the one fine-tuned (the T5's codes decode through it), and the
        residual branch stays as it was."""
        return not self.residual_levels or set(RESIDUAL_PARTS) <= set(self.train.freeze)

    @property
    def residual_input_dim(self) -> int:
        """Channels the residual decoder reads per step: the base code, the residual code and a
        flag saying whether it is there."""
        return len(self.levels) + len(self.residual_levels) + 1


class SAVAE(nn.Module):
    def __init__(self, cfg: SAVAEConfig, mean=None, std=None):
        super().__init__()
        cfg.validate()
        self.cfg = cfg
        c = len(cfg.levels)
        self.encoder = Encoder(cfg.feature_dim, c, cfg.width, cfg.depth, cfg.dilation_growth, cfg.down_t)
        self.quantizer = FSQ(cfg.levels)
        self.shape_embedding = ShapeEmbedding(cfg.num_betas, cfg.shape_hidden, cfg.token_dim)
        self.decoder = Decoder(c, cfg.token_dim, cfg.feature_dim, cfg.base_decoder_width, cfg.depth, cfg.dilation_growth,
                               cfg.down_t)
        if cfg.residual_levels:
            r = len(cfg.residual_levels)
            self.residual_encoder = Encoder(cfg.feature_dim, r, cfg.width, cfg.depth, cfg.dilation_growth, cfg.down_t)
            self.residual_quantizer = FSQ(cfg.residual_levels)
            self.residual_shape_embedding = ShapeEmbedding(cfg.num_betas, cfg.shape_hidden, cfg.token_dim)
            self.residual_decoder = Decoder(cfg.residual_input_dim, cfg.token_dim, cfg.feature_dim, cfg.width,
                                            cfg.depth, cfg.dilation_growth, cfg.down_t)
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

    @property
    def has_residual(self) -> bool:
        return bool(self.cfg.residual_levels)

    def encode(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Normalized canonical features (B, T, D) -> codes (B, T/4, C), indices (B, T/4)."""
        return self.quantizer(self.encoder(x))

    def encode_residual(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """The residual code of the same motion: codes (B, T/4, R), indices (B, T/4)."""
        if not self.has_residual:
            raise ShapeMoveError("this SA-VAE has no residual code")
        return self.residual_quantizer(self.residual_encoder(x))

    def residual_input(self, codes: torch.Tensor, residual: torch.Tensor,
                       present: torch.Tensor | None = None) -> torch.Tensor:
        """What the residual decoder reads per step: base codes (B, N, C), residual codes (B, N, R)
        and a 0/1 flag; ``present`` (B,) 0 for a row reads it from its base codes alone (training)."""
        B, N, _ = codes.shape
        r = len(self.cfg.residual_levels)
        if residual.shape != (B, N, r):
            raise ShapeMoveError(f"residual codes must be {(B, N, r)}, got {tuple(residual.shape)}")
        flag = codes.new_ones(B, N, 1) if present is None else present.to(codes).reshape(B, 1, 1).expand(B, N, 1)
        return torch.cat([codes, residual * flag, flag], dim=-1)

    def decode(self, codes: torch.Tensor, betas: torch.Tensor, residual: torch.Tensor | None = None) -> torch.Tensor:
        """Codes (B, N, C), betas (B, 10) -> normalized shape-aware features (B, 4N, D), by the base
        decoder; with ``residual`` codes (B, N, R), by the residual branch."""
        if residual is None:
            return self.decoder(codes, self.shape_embedding(betas))
        if not self.has_residual:
            raise ShapeMoveError("this SA-VAE has no residual code to decode")
        return self._decode_residual(codes, residual, betas)

    def _decode_residual(self, codes, residual, betas, present=None) -> torch.Tensor:
        """The residual branch: base and residual codes (``residual_input``) + betas -> features."""
        stream = self.residual_input(codes, residual, present)
        return self.residual_decoder(stream, self.residual_shape_embedding(betas))

    def decode_indices(self, indices: torch.Tensor, betas: torch.Tensor) -> torch.Tensor:
        return self.decode(self.quantizer.indices_to_codes(indices), betas)

    def encode_tokens(self, x: torch.Tensor) -> torch.Tensor:
        """Normalized canonical features (B, T, D) -> tokens (B, T/4): the base indices, with the
        residual packed in (``motion_codes.pack``) when the codec has one."""
        return self.tokens_of_codes(self.encode(x)[0], self.encode_residual(x)[0] if self.has_residual else None)

    def tokens_of_codes(self, codes: torch.Tensor, residual: torch.Tensor | None = None) -> torch.Tensor:
        """Base codes (B, N, C) and residual codes (B, N, R) or None -> tokens (B, N): the base
        indices, the residual's packed in (``motion_codes.pack``) when given."""
        base = self.quantizer.codes_to_indices(codes.detach())
        if residual is None:
            return base
        return pack(base, self.residual_quantizer.codes_to_indices(residual.detach()), self.quantizer.codebook_size)

    @torch.no_grad()
    def decode_tokens_long(self, tokens: torch.Tensor, betas: torch.Tensor) -> torch.Tensor:
        """Tokens (B, N) (base, or with packed residuals) + betas -> normalized shape-aware features
        (``decode_long``): through the residual branch when every step carries a residual, else the
        base codes through the base decoder (what the T5 writes; a codec without a residual code
        decodes the base of every token)."""
        base, res = unpack(torch.as_tensor(tokens).long(), self.quantizer.codebook_size)
        codes = self.quantizer.indices_to_codes(base)
        if not self.has_residual or not bool((res >= 0).all()):
            return self.decode_long(codes, betas)
        if int(res.max()) >= self.residual_quantizer.codebook_size:
            raise ShapeMoveError(f"residual code out of range [0, {self.residual_quantizer.codebook_size})")
        return self.decode_long(codes, betas, residual=self.residual_quantizer.indices_to_codes(res))

    def forward(self, x: torch.Tensor, betas: torch.Tensor, base: bool = False) -> dict:
        """Training's pass: encode, decode. ``base`` decodes the base codes by the base decoder even
        in a residual codec (``SAVAEConfig.trains_base``)."""
        codes, indices = self.encode(x)
        if not self.has_residual or base:
            return {"recon": self.decode(codes, betas), "codes": codes, "indices": indices}
        residual, _ = self.encode_residual(x)
        present = None
        if self.training and self.cfg.residual_dropout > 0:
            present = (torch.rand(x.shape[0], device=x.device) >= self.cfg.residual_dropout).float()
        return {"recon": self._decode_residual(codes, residual, betas, present), "codes": codes, "indices": indices}

    @torch.no_grad()
    def decode_long(self, codes: torch.Tensor, betas: torch.Tensor, chunk: int | None = None, overlap: int = 4,
                    residual: torch.Tensor | None = None) -> torch.Tensor:
        """Decode a sequence longer than the training window: overlapping chunks of ``chunk`` codes
        (default window/4), each with its own shape token, cross-faded over ``overlap`` codes, so
        every frame sits as close to a shape token as in training. No gradient (``decode_chunked``
        is the same with one)."""
        return self.decode_chunked(codes, betas, chunk, overlap, residual)

    def chunking(self, chunk: int | None = None, overlap: int = 4) -> tuple[int, int]:
        """The codes per chunk and the codes two neighbouring chunks share, as ``decode_long`` cuts
        a sequence (chunks start every chunk - overlap codes)."""
        chunk = chunk or self.cfg.train.window // self.cfg.downsample
        return chunk, min(overlap, chunk // 2)  # short training windows give short chunks

    def decode_chunked(self, codes: torch.Tensor, betas: torch.Tensor, chunk: int | None = None, overlap: int = 4,
                       residual: torch.Tensor | None = None) -> torch.Tensor:
        """``decode_long`` with gradients (``code_search``)."""
        chunk, overlap = self.chunking(chunk, overlap)
        n, up = codes.shape[1], self.cfg.downsample
        if n <= chunk:
            return self.decode(codes, betas, residual)
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
            res = None if residual is None else residual[:, s:s + chunk]
            out[:, s * up:(s + chunk) * up] += self.decode(codes[:, s:s + chunk], betas, res) * w
            total[s * up:(s + chunk) * up] += w
        return out / total


@torch.no_grad()
def add_residual(model: SAVAE, base: SAVAE) -> None:
    """Start ``model`` (a residual codec) from ``base``, a trained codec of the same network without
    one: every weight of ``base`` is kept, so ``model`` encodes the same base codes and decodes them
    exactly as ``base`` does. The residual branch starts as a copy of the base one (its decoder's
    weights on the residual channels and flag as a fresh layer's: at zero the residual would get
    no gradient to learn from), the residual encoder from the base encoder's layers but its last."""
    if base.has_residual or not model.has_residual:
        raise ShapeMoveError("add_residual: needs a codec without a residual code and one with it")
    if not isinstance(base.decoder.lift, nn.Linear):
        raise ShapeMoveError("add_residual: the base codec's decoder reads raw codes (shape_token_dim = "
                             "number of levels); a residual code needs its per-step projection")
    theirs = base.state_dict()
    mine = model.state_dict()
    last = len(base.encoder.net) - 1
    for k, v in theirs.items():
        mine[k] = v.clone()
        if k.startswith(("decoder.", "shape_embedding.")):
            r = "residual_" + k
            if k == "decoder.lift.weight":  # the base columns kept, the residual ones as initialised
                w = mine[r].clone()
                w[:, :v.shape[1]] = v
                mine[r] = w
            else:
                mine[r] = v.clone()
        elif k.startswith("encoder.net.") and not k.startswith(f"encoder.net.{last}."):
            mine["residual_" + k] = v.clone()
    model.load_state_dict(mine)


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
