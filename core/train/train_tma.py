"""Train the TMA (text-motion alignment, Human TOMATO's evaluator). Read top to bottom.

    train_tma(data="DATA", out="runs/tma", config="small")                          # one process
    torchrun --nproc_per_node 2 -m shapemove train tma --data DATA --out RUN        # DDP

1. the captions of the train and val splits are read by the frozen pretrained MiniLM once (their
   token states are cached in memory); the TMA's own text layers are trained on top of them.
   (``model.text_encoder="sentencepiece"``: a sentencepiece tokenizer trained on the captions,
   ``out/tokenizer/``, the TMA of models from before the pretrained encoder);
2. each step draws ``batch_size`` distinct training clips; each gives one of its captions and a
   random crop (up to ``max_frames``) of either its normalized-body or its shape-aware features
   (``shape_aware_share``), so the model aligns text with motion whatever the body;
3. symmetric InfoNCE (identical captions are not negatives of each other);
4. every ``val_every`` steps: R-precision top1/top3 and matching score on the val split.
Writes ``out/last.pt`` (full training state, atomic; ``resume=True`` continues from it),
``out/tma.pt`` (weights + metadata) at the end, ``config.json`` and ``log.jsonl``. Batches are a
pure function of (seed, step), so an interrupted and resumed run equals an uninterrupted one.
"""
from __future__ import annotations

import os
import random
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import torch
from torch import nn
from torch.nn.parallel import DistributedDataParallel as DDP

from ..atomic import atomic_write_json
from ..config_presets import load_config, refuse_unknown
from ..data.actions import stored_labels
from ..data.paraphrase_bank import BANK_SHARE, training_caption
from ..errors import ShapeMoveError
from ..eval.tma_embed import eval_pairs, score_pairs
from ..models.text_encoder import StateCache, fingerprint, load_text_encoder
from ..models.tma import TMA, TMAConfig
from ..models.tma_embed import KIND, pad_batch, text_inputs
from ..models.tokenizer import load_tokenizer, tokenizer_from_sentencepiece, train_sentencepiece
from . import distributed
from .checkpoint_cadence import finish, save_if_due
from .run_log import StepLog
from .warmup_cosine import OptimizerSettings, adamw_warmup_cosine
from .checkpoint import load_checkpoint, make_metadata, save_checkpoint, stats_hash
from .motion_dataset import load_stats, read_split
from .optimizer_step import optimizer_step
from .t5_dataset import read_lines
from .resume import restore, rng_state

RESUME_IGNORES = ("steps",)  # a resumed run may be extended; anything else must match
FEATURE_KINDS = ("norm_joint_vecs", "new_joint_vecs")


@dataclass
class TMATrainConfig(OptimizerSettings):
    model: dict = field(default_factory=lambda: asdict(TMAConfig()))  # sentencepiece: vocab_size set from it
    steps: int = 6000
    batch_size: int = 64
    lr: float = 2e-4
    vocab_size: int = 2000          # sentencepiece only: upper bound (a small corpus gets fewer pieces)
    shape_aware_share: float = 0.5  # share of crops from new_joint_vecs (else norm_joint_vecs)
    bank_share: float = BANK_SHARE  # share of captions drawn from the paraphrase bank (data/paraphrase_bank.py)
    seed: int = 0
    log_every: int = 50
    val_every: int = 500
    ckpt_every: int = 500

    @classmethod
    def tiny(cls) -> "TMATrainConfig":
        return cls(model=asdict(TMAConfig.tiny(0)), steps=40, batch_size=8, lr=1e-3, warmup_steps=5, vocab_size=300,
                   log_every=5, val_every=20, ckpt_every=20)

    @classmethod
    def paper(cls) -> "TMATrainConfig":
        """TMR/TMA-sized encoders (6 layers, 256 wide)."""
        return cls(model=asdict(TMAConfig(layers=6)), steps=20000, batch_size=64, lr=1e-4, warmup_steps=500,
                   val_every=1000, ckpt_every=1000)

    @classmethod
    def load(cls, config=None) -> "TMATrainConfig":
        """A preset (``config_presets.PRESETS``; None = small), a JSON file, a TMAConfig (small training
        settings) or an instance."""
        if isinstance(config, cls):
            return cls(**asdict(config))
        if isinstance(config, TMAConfig):
            return cls(model=asdict(config))

        def from_json(data, p):
            refuse_unknown(data, asdict(cls()), p, "TMA config")
            model = {**asdict(TMAConfig()), **data.pop("model", {})}
            refuse_unknown(model, asdict(TMAConfig()), p, "TMA model")
            return cls(model=model, **data)

        return load_config("TMA", config, {"tiny": cls.tiny, "small": cls, "paper": cls.paper}, from_json)

    def validate(self) -> None:
        if self.steps < 1 or self.batch_size < 2:
            raise ShapeMoveError("TMA training needs steps >= 1 and batch_size >= 2 (contrastive loss)")
        if not (self.lr > 0 and 0 <= self.shape_aware_share <= 1 and 0 <= self.bank_share <= 1):
            raise ShapeMoveError("TMA config: lr must be > 0, shape_aware_share and bank_share in [0, 1]")
        m = self.model
        if m["dim"] % m["heads"] or m["dim"] % 2 or m["max_frames"] < 4:
            raise ShapeMoveError("TMA model: dim must be even and divisible by heads; max_frames >= 4")


class TMAClips:
    """The training clips: ids, captions and both feature arrays (normalized with Mean/Std)."""

    def __init__(self, root: Path, split: str, mean: np.ndarray, std: np.ndarray):
        self.ids, self.captions, self.labels, self.feats = [], [], [], []
        for cid in read_split(root, split):
            caps = read_lines(root / "texts" / f"{cid}.txt")
            if not caps:
                continue
            pair = []
            for kind in FEATURE_KINDS:
                f = root / kind / f"{cid}.npy"
                if not f.is_file():
                    raise ShapeMoveError(f"{root}: clip '{cid}' of {split}.txt has no {kind}/{cid}.npy")
                a = np.load(f).astype(np.float32)
                if a.ndim != 2 or a.shape[1] != len(mean) or len(a) < 4:
                    raise ShapeMoveError(f"{f}: features of shape {a.shape}, expected (frames >= 4, {len(mean)})")
                pair.append((a - mean) / std)
            self.ids.append(cid)
            self.captions.append(caps)
            self.labels.append(stored_labels(root, cid))
            self.feats.append(pair)

    def __len__(self) -> int:
        return len(self.ids)

    def batch(self, c: TMATrainConfig, step: int, rank: int = 0, world: int = 1):
        """This rank's share of step ``step``'s batch: (texts, feats (B,T,D), lengths (B,)).
        A pure function of (seed, step): distinct clips, one caption, one crop each."""
        rng = np.random.default_rng([c.seed, step])
        n = min(c.batch_size, len(self))
        picks = rng.permutation(len(self))[:n]
        max_frames = c.model["max_frames"]
        texts, crops = [], []
        for i in picks:
            texts.append(training_caption(self.captions[i], self.labels[i], random.Random(int(rng.integers(1 << 31))),
                                          c.bank_share))
            f = self.feats[i][int(rng.random() < c.shape_aware_share)]
            start = int(rng.integers(0, len(f) - max_frames + 1)) if len(f) > max_frames else 0
            crops.append(f[start:start + max_frames])
        share = slice(rank * n // world, (rank + 1) * n // world)
        x, lengths = pad_batch(crops[share])
        return texts[share], x, lengths


class _Pairs(nn.Module):
    """TMA + loss as one forward (what DistributedDataParallel needs to synchronise gradients)."""

    def __init__(self, tma: TMA):
        super().__init__()
        self.tma = tma

    def forward(self, ids, mask, feats, lengths, keys):
        return self.tma.loss(self.tma.text(ids, mask), self.tma.motion(feats, lengths), keys)


def caption_key(text: str) -> str:
    return " ".join(text.lower().replace(".", " ").split())


def train_tma(data, out, config=None, steps: int | None = None, batch_size: int | None = None,
              lr: float | None = None, resume: bool = False, body: str | None = None, device: str | None = None,
              progress=None, cancel=None, verbose: bool = True) -> dict:
    """Train (or resume) a TMA on the dataset folder ``data``; returns the last metrics:
    {"step", "lr", "train": {"loss"}, "val": {"r_precision_top1", "r_precision_top3",
    "matching_score", "clips"}, "sec_per_step"}.

    ``config``: "small" (default), "paper", "tiny", a JSON file, a TMAConfig or a TMATrainConfig;
    ``steps``/``batch_size``/``lr`` override it. progress(fraction, message) is called every
    ``log_every`` steps; when cancel() returns True training stops after saving ``last.pt``.
    """
    c = TMATrainConfig.load(config)
    for name, v in (("steps", steps), ("batch_size", batch_size), ("lr", lr)):
        if v is not None:
            setattr(c, name, type(getattr(c, name))(v))
    c.validate()
    data, out = Path(data), Path(out)
    if not data.is_dir():
        raise ShapeMoveError(f"dataset folder not found: {data}")
    with distributed.process_group(device) as dist:
        return _train(data, out, c, resume, body or "openbody", dist, progress, cancel, verbose)


def _text_reader(data: Path, out: Path, c: TMATrainConfig, dist, texts: list[str], verbose: bool):
    """MiniLM with every caption's token states cached, or (old TMAs) the sentencepiece tokenizer."""
    if c.model.get("text_encoder", "minilm") == "minilm":
        cache = StateCache(load_text_encoder())
        cache.add(texts, progress=dist.is_main and verbose)
        return cache

    tok_dir = out / "tokenizer"
    if not (tok_dir / "tokenizer.json").is_file():
        if dist.is_main:
            texts = [t for cid in read_split(data, "train") for t in read_lines(data / "texts" / f"{cid}.txt")]
            if not texts:
                raise ShapeMoveError(f"{data}: the train split has no captions (texts/ID.txt)")
            tok = tokenizer_from_sentencepiece(train_sentencepiece(texts, out / "spm" / "sp", c.vocab_size, c.seed))
            tmp = out / "tokenizer.tmp"
            tok.save_pretrained(str(tmp))
            if tok_dir.exists():
                import shutil

                shutil.rmtree(tok_dir)
            os.replace(tmp, tok_dir)
    distributed.barrier(dist)
    tok = load_tokenizer(tok_dir)
    c.model["vocab_size"] = len(tok)
    return tok


def _train(data, out, c, resume, body_name, dist, progress, cancel, verbose) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    # -- data and tokenizer ------------------------------------------------------------------
    mean, std = load_stats(data)
    train_set = TMAClips(data, "train", mean, std)
    if len(train_set) < 2:
        raise ShapeMoveError(f"{data}: the train split has {len(train_set)} clip(s) with captions; need at least 2")
    if len(train_set) < c.batch_size and dist.is_main and verbose:
        print(f"note: {len(train_set)} training clips < batch_size {c.batch_size}: batches hold every clip once")
    if min(c.batch_size, len(train_set)) < 2 * dist.world_size:
        raise ShapeMoveError(f"batch of {min(c.batch_size, len(train_set))} clips is too small for {dist.world_size} processes")
    val_feats, val_texts = eval_pairs(data, read_split(data, "val"))
    tok = _text_reader(data, out, c, dist, [t for caps in train_set.captions for t in caps] + val_texts, verbose)
    cfg = TMAConfig(**c.model)
    # -- model, optimizer, resume ------------------------------------------------------------
    torch.manual_seed(c.seed)  # same initial weights on every rank
    model = TMA(cfg).to(dist.device)
    optimizer, scheduler = adamw_warmup_cosine(model.parameters(), c)
    step = 0
    last = out / "last.pt"
    if resume and last.is_file():
        ckpt = load_checkpoint(last, map_location=dist.device, kind=KIND, config=asdict(c), ignore=RESUME_IGNORES,
                               stats_hash_=stats_hash(mean, std))
        step = restore(ckpt, model, optimizer, scheduler)
    elif resume and dist.is_main and verbose:
        print(f"no checkpoint in {out}: starting from scratch")
    pairs = _Pairs(model)
    if dist.enabled:
        pairs = DDP(pairs, device_ids=[dist.device.index] if dist.device.type == "cuda" else None)

    def save(final: bool = False) -> None:
        if not dist.is_main:
            return
        extra = {}
        if cfg.text_encoder == "minilm":
            extra["text_encoder"] = fingerprint()
        meta = make_metadata(KIND, asdict(c), body_name, mean, std, step, data=str(data), **extra)
        save_checkpoint(last, {"model": model.state_dict(), "optimizer": optimizer.state_dict(),
                               "scheduler": scheduler.state_dict(), "step": step, "rng": rng_state()}, meta)
        if final:
            save_checkpoint(out / "tma.pt", {"model": model.state_dict()}, meta)

    def validate() -> dict:
        val = score_pairs(model, tok, mean, std, val_feats, val_texts) if len(val_feats) >= 2 else {}
        model.train()
        return val

    if dist.is_main:
        atomic_write_json(out / "config.json", asdict(c))
    log = StepLog(out, c.steps, step, dist, progress, "train tma", verbose)
    model.train()
    # -- loop ----------------------------------------------------------------------------------
    while step < c.steps:
        if distributed.broadcast_flag(bool(cancel and dist.is_main and cancel()), dist):
            break
        texts, feats, lengths = train_set.batch(c, step, dist.rank, dist.world_size)
        text_a, text_b = text_inputs(model, tok, texts)
        loss = pairs(text_a.to(dist.device), text_b.to(dist.device), feats.to(dist.device),
                     lengths.to(dist.device), [caption_key(t) for t in texts])
        optimizer_step(loss, optimizer, scheduler, model.parameters(), c.grad_clip)
        step += 1
        log.bar.update(1)
        done = step == c.steps
        if done or step % c.log_every == 0 or step % c.val_every == 0:
            log.log(step, scheduler.get_last_lr()[0], {"loss": loss.item()},
                    {"loss": ("train", "loss"), "r1": ("val", "r_precision_top1")},
                    validate if done or step % c.val_every == 0 else None)
        save_if_due(save, step, c.ckpt_every, c.steps, dist)
    return finish(save, log.bar, step, c.steps, dist, log.metrics)


def from_cli(args, cancel=None) -> dict:
    """Entry point of `python -m shapemove train tma` (cli/train.py): reads args.data, args.out,
    args.config (small|paper|tiny|JSON), args.steps, args.resume, args.device, args.body, args.quiet
    and, when the parser has them, args.batch_size and args.lr."""
    return train_tma(args.data, args.out, args.config, steps=args.steps, batch_size=getattr(args, "batch_size", None),
                     lr=getattr(args, "lr", None), resume=args.resume, body=getattr(args, "body", None),
                     device=args.device, verbose=not args.quiet, cancel=cancel)
