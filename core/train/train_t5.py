"""Train ShapeMove's T5 (stage 2). Read top to bottom like nanoGPT's train.py.

    train_t5(data="DATA", vae="runs/vae/savae.pt", out="runs/t5")                 # one process
    torchrun --nproc_per_node 2 -m shapemove train t5 --data DATA --vae V --out R  # DDP

1. the frozen SA-VAE turns every clip's normalized motion into FSQ tokens (cached in ``out``);
   the motion vocabulary is its FSQ codebook (levels [8,5,5,5] = 1000 codes);
2. ``encoder="minilm"`` (default): the frozen pretrained MiniLM reads every caption and shape text
   once (token states cached in memory), and a T5 decoder learns to cross-attend to them;
   ``encoder="t5"``: a sentencepiece tokenizer is trained on the captions + shape texts and a whole
   T5 learns from scratch (or the tokenizer of a pretrained T5 folder given as ``base_model`` is
   extended and that T5 is fine-tuned);
3. model + [BETA] head learn text -> [BETA] [SOM] codes [EOM] (+ optional motion-to-text examples,
   T5 encoder only);
4. ``head_steps`` more steps train the [BETA] head alone on heights and waists in cm, the T5 frozen
   (``beta_head_refit.py``). Steps count on from ``steps``: a run resumes in either phase.
Writes ``out/last.pt`` (full training state, atomic; ``resume=True`` continues from it) and, at
the end, ``out/t5/`` (weights + beta head + metadata, the T5's tokenizer, and the training captions
and actions with their MiniLM vectors: ``known_texts.py``).
"""
from __future__ import annotations

import random
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import torch
from torch.nn.parallel import DistributedDataParallel as DDP

from ..atomic import atomic_path
from ..config_presets import load_config, refuse_unknown
from ..data.paraphrase_bank import BANK_SHARE
from ..errors import ShapeMoveError
from ..models.shapemove_t5 import ShapeMoveT5, T5Size, size_from_dict
from ..models.tokenizer import add_motion_tokens, load_tokenizer, tokenizer_from_sentencepiece, train_sentencepiece
from . import distributed
from .checkpoint_cadence import finish, save_if_due
from .run_log import StepLog
from .warmup_cosine import OptimizerSettings, adamw_warmup_cosine
from .checkpoint import config_differences, load_checkpoint, save_checkpoint
from .t5_dataset import T2MExamples, all_texts, collate, collate_minilm, tokenize_clips
from .optimizer_step import optimizer_step
from .resume import restore, rng_state

KIND = "shapemove-t5"
HEAD_KEYS = ("head_steps", "head_batch_size", "head_lr", "head_measure_weight", "head_synthetic_share",
             "head_synthetic_bodies")  # may change on resume


@dataclass
class T5TrainConfig(OptimizerSettings):
    size: dict = field(default_factory=lambda: asdict(T5Size()))
    steps: int = 3000
    batch_size: int = 32
    lr: float = 5e-4
    beta_weight: float = 1.0
    max_codes: int = 50            # 10 s at 20 fps, 4x downsampling
    m2t_share: float = 0.0         # share of motion-to-text examples (the paper's pre-training; T5 encoder)
    bank_share: float = BANK_SHARE  # share of captions drawn from the paraphrase bank (data/paraphrase_bank.py)
    action_balance: float = 0.0    # clip sampling weight 1 / (clips of its main action) ** this (1 = actions equally)
    null_share: float = 0.0        # share of prompts trained without motion text (classifier-free guidance)
    encoder: str = "minilm"        # "minilm" (frozen pretrained MiniLM + T5 decoder) or "t5" (whole T5)
    vocab_size: int = 2000
    seed: int = 0
    log_every: int = 50
    ckpt_every: int = 250
    head_steps: int = 0            # [BETA] head alone after the main steps (beta_head_refit.py)
    head_batch_size: int = 256
    head_lr: float = 3e-4
    head_measure_weight: float = 0.3  # per cm of height + waist error, beside the betas' L1
    head_synthetic_share: float = 0.0  # share of head-phase examples describing new random bodies
    head_synthetic_bodies: int = 4000  # size of that pool of bodies (their texts encoded once)

    @classmethod
    def tiny(cls) -> "T5TrainConfig":
        return cls(size=asdict(T5Size.tiny()), steps=20, batch_size=4, warmup_steps=2, log_every=5, ckpt_every=10,
                   vocab_size=300, max_codes=16, head_synthetic_bodies=48)

    def validate(self, base_model=None) -> None:
        if self.encoder not in ("minilm", "t5"):
            raise ShapeMoveError(f"T5 config: encoder must be 'minilm' or 't5', got {self.encoder!r}")
        if base_model is not None and self.encoder != "t5":
            raise ShapeMoveError("--base-model is a pretrained T5 folder: use it with \"encoder\": \"t5\" "
                                 "(the default encoder is the pretrained MiniLM)")
        if self.encoder == "minilm" and self.m2t_share:
            raise ShapeMoveError("motion-to-text examples (m2t_share) need the T5 encoder; set m2t_share to 0")
        if self.steps < 1 or self.batch_size < 1 or self.max_codes < 1:
            raise ShapeMoveError("T5 config: steps, batch_size and max_codes must be >= 1")
        if not 0 <= self.bank_share <= 1:
            raise ShapeMoveError(f"T5 config: bank_share must be in [0, 1], got {self.bank_share}")
        if not 0 <= self.action_balance <= 1:
            raise ShapeMoveError(f"T5 config: action_balance must be in [0, 1], got {self.action_balance}")
        if not 0 <= self.null_share < 1:
            raise ShapeMoveError(f"T5 config: null_share must be in [0, 1), got {self.null_share}")
        if (self.head_steps < 0 or self.head_batch_size < 1 or self.head_lr <= 0 or self.head_measure_weight < 0
                or not 0 <= self.head_synthetic_share <= 1 or self.head_synthetic_bodies < 1):
            raise ShapeMoveError("T5 config: head_steps >= 0, head_batch_size >= 1, head_lr > 0, "
                                 "head_measure_weight >= 0, head_synthetic_share in [0, 1] and head_synthetic_bodies >= 1 are required")

    @classmethod
    def paper(cls) -> "T5TrainConfig":
        """The paper's model: a whole T5 of T5-base's sizes (12+12 layers, 768 wide) trained from
        scratch here (``--base-model`` loads pretrained weights instead); a GPU run."""
        return cls(size=asdict(T5Size(d_model=768, d_ff=3072, num_layers=12, num_decoder_layers=12, num_heads=12)),
                   encoder="t5", steps=20000, batch_size=32, lr=2e-4, warmup_steps=1000, log_every=100,
                   ckpt_every=1000)

    @classmethod
    def load(cls, name_or_path: str | None) -> "T5TrainConfig":
        """A preset (``config_presets.PRESETS``; None = small) or a JSON file of settings."""
        def from_json(data, p):
            refuse_unknown(data, asdict(cls()), p, "T5 config")
            return cls(**data)

        return load_config("T5", name_or_path, {"tiny": cls.tiny, "small": cls, "paper": cls.paper}, from_json)


def vae_stamp(path: Path) -> str:
    """What the token cache (``out/tokens.npz``) records of the VAE file that made it: its path
    and modification time (another file, or the same one changed, tokenizes again)."""
    return f"{Path(path).resolve()}:{Path(path).stat().st_mtime_ns}"


def load_vae(path):
    from ..models.savae import load_savae

    return load_savae(path)


def train_t5(data, vae, out, config: T5TrainConfig | None = None, base_model=None, resume: bool = False,
             steps: int | None = None, device: str | None = None, progress=None, cancel=None, verbose: bool = True) -> dict:
    c = config or T5TrainConfig()
    if steps is not None:
        c.steps = int(steps)
    if base_model is not None and c.encoder == "minilm":
        c.encoder = "t5"  # a pretrained T5 folder brings its own encoder
    c.validate(base_model)
    data, out = Path(data), Path(out)
    with distributed.process_group(device) as dist:
        return _train(data, Path(vae), out, c, base_model, resume, dist, progress, cancel, verbose)


def _train(data, vae_path, out, c, base_model, resume, dist, progress, cancel, verbose) -> dict:

    out.mkdir(parents=True, exist_ok=True)
    # -- 1. motion tokens from the frozen SA-VAE (cached per VAE file) -------------------------
    vae = load_vae(vae_path)
    from .motion_dataset import read_split

    ids = sorted(set(read_split(data, "train")) | set(read_split(data, "val")))
    cache = out / "tokens.npz"
    stamp = vae_stamp(vae_path)
    tokens = None
    if cache.is_file():
        z = np.load(cache, allow_pickle=False)
        if str(z["__vae__"]) == stamp:
            tokens = {k: z[k] for k in z.files if k != "__vae__"}
    if tokens is None:
        tokens = tokenize_clips(vae, data, ids)
        if dist.is_main:
            with atomic_path(cache, suffix=".npz") as tmp:
                np.savez(tmp, __vae__=np.array(stamp), **tokens)
    num_codes = int(vae.quantizer.codebook_size)
    # -- 2. text reader: MiniLM states of every training text, or the T5's tokenizer ------------
    from ..models.text_encoder import StateCache, load_text_encoder

    train_ids = read_split(data, "train")
    states = StateCache(load_text_encoder())  # also gives the known captions' vectors at the end
    torch.manual_seed(c.seed)
    if c.encoder == "minilm":
        states.add(all_texts(data, train_ids), progress=dist.is_main and verbose)
        tok = states
        model = ShapeMoveT5.build_minilm(num_codes, size_from_dict(c.size), beta_weight=c.beta_weight)
        if model.memory_k:  # the training clips' tokens, read back by caption similarity
            from ..models.motion_memory import MotionMemory

            model.memory = MotionMemory.from_dataset(data, train_ids, tokens, states)
    else:
        tok_dir = out / "tokenizer"
        if (tok_dir / "tokenizer.json").is_file():
            tok = load_tokenizer(tok_dir, num_codes=num_codes)
        elif base_model is not None:
            tok = add_motion_tokens(load_tokenizer(Path(base_model), require_json=False, num_codes=num_codes), num_codes)
        else:
            texts = all_texts(data, train_ids)
            tok = tokenizer_from_sentencepiece(train_sentencepiece(texts, out / "spm" / "sp", c.vocab_size, c.seed),
                                               num_codes)
        if dist.is_main and not (tok_dir / "tokenizer.json").is_file():
            tok.save_pretrained(str(tok_dir))
        model = ShapeMoveT5.build(tok, size_from_dict(c.size), base_model=base_model, beta_weight=c.beta_weight)
    # -- 3. model, optimizer, resume ---------------------------------------------------------
    model = model.to(dist.device)
    optimizer, scheduler = adamw_warmup_cosine(model.parameters(), c)
    step, rng = 0, random.Random(c.seed + 1000 * dist.rank)
    head_state = None
    last = out / "last.pt"
    if resume and last.is_file():
        ckpt = load_checkpoint(last, map_location=dist.device, kind=KIND)  # weights_only=True: never unpickles code
        saved = {**asdict(T5TrainConfig()), **ckpt["config"]}  # options added since: the run had their defaults
        diff = config_differences(saved, asdict(c), ignore=("steps",) + HEAD_KEYS)
        if ckpt.get("kind") != KIND or diff:
            raise ShapeMoveError(f"{last}: cannot resume, the configuration differs ({', '.join(diff) or 'kind'})")
        step = restore(ckpt, model, optimizer, scheduler)
        if step > c.steps and ckpt.get("head_optimizer") is None:
            raise ShapeMoveError(f"{last}: saved at step {step}, beyond the {c.steps} main steps, without a head phase")
        head_state = ckpt.get("head_optimizer")
        rng.setstate(ckpt["py_rng_examples"])
    raw = model
    if dist.enabled:
        model = DDP(model, find_unused_parameters=True)
    train_set = T2MExamples(data, "train", tokens, c.max_codes, c.m2t_share, bank_share=c.bank_share,
                            action_balance=c.action_balance, null_share=c.null_share)
    meta = {"vae": str(vae_path), "vae_body": vae.metadata.get("body"), "config": asdict(c),
            "downsample": vae.cfg.downsample, "max_codes": c.max_codes, "data": str(data),
            "base_model": str(base_model) if base_model is not None else None}

    total = c.steps + c.head_steps
    head_opt = torch.optim.AdamW(raw.beta_head.parameters(), lr=c.head_lr, weight_decay=c.weight_decay)
    if head_state is not None:
        head_opt.load_state_dict(head_state)

    def save(final: bool = False):
        if not dist.is_main:
            return
        save_checkpoint(last, {"kind": KIND, "config": asdict(c), "model": raw.state_dict(),
                               "optimizer": optimizer.state_dict(), "scheduler": scheduler.state_dict(),
                               "step": step, "rng": rng_state(), "py_rng_examples": rng.getstate(),
                               "head_optimizer": head_opt.state_dict() if step > c.steps else None},
                        {"format": 1, "kind": KIND})
        if final:
            from ..models.known_texts import build_known

            raw.save(out / "t5", None if c.encoder == "minilm" else tok, meta | {"step": step},
                     known=build_known(data, train_ids, states), memory=raw.memory)

    log = StepLog(out, total, step, dist, progress, "train t5", verbose)
    model.train()
    while step < c.steps:
        if distributed.broadcast_flag(bool(cancel and dist.is_main and cancel()), dist):
            break
        batch = [train_set.sample(rng) for _ in range(c.batch_size // dist.world_size)]
        if c.encoder == "minilm":
            (x, mask, seg), labels, betas, memory = collate_minilm(batch, states, raw.vocab, raw, rng)
            res = model(x.to(dist.device), mask.to(dist.device), labels.to(dist.device), betas.to(dist.device),
                        seg.to(dist.device), tuple(m.to(dist.device) for m in memory) if memory else None)
        else:
            input_ids, attn, labels, betas = (t.to(dist.device) for t in collate(batch, tok, raw.vocab))
            res = model(input_ids, attn, labels, betas)
        optimizer_step(res["loss"], optimizer, scheduler, raw.parameters(), c.grad_clip)
        step += 1
        log.bar.update(1)
        if step % c.log_every == 0 or step == c.steps:
            log.log(step, scheduler.get_last_lr()[0],
                    {"loss": float(res["loss"].detach()), "ce": float(res["ce"]), "l1": float(res["l1"])},
                    {"ce": ("train", "ce"), "l1": ("train", "l1")})
        save_if_due(save, step, c.ckpt_every, total, dist)
    # -- 4. the [BETA] head alone on heights and waists (beta_head_refit.py) -------------------
    total = c.steps + c.head_steps  # c.steps may have been shortened while training (tools/gpu_t5.py)
    if c.steps <= step < total:
        from .beta_head_refit import HeadExamples, head_loss

        head_set = HeadExamples(train_set, vae.metadata.get("body"), c.seed, c.head_synthetic_bodies
                                if c.head_synthetic_share > 0 else 0)
        if head_set.pool_texts and c.encoder == "minilm":
            states.add(head_set.pool_texts, progress=dist.is_main and verbose)  # encoded once
        raw.eval()  # the T5 as at generation time (no dropout); only the head learns
        raw.beta_head.train()
    while c.steps <= step < total:
        if distributed.broadcast_flag(bool(cancel and dist.is_main and cancel()), dist):
            break
        motions, shapes, betas = head_set.batch(rng, max(1, c.head_batch_size // dist.world_size),
                                                c.head_synthetic_share)
        with torch.no_grad():
            h = raw.beta_state(tuple(x.to(dist.device) for x in raw.inputs_for(states if c.encoder == "minilm" else tok,
                                                                               motions, shapes)))
        loss, l1, cm = head_loss(raw.beta_head, h, betas.to(dist.device), head_set.measure, c.head_measure_weight)
        for g in head_opt.param_groups:  # linear decay to 0 over the head phase
            g["lr"] = c.head_lr * (total - step) / c.head_steps
        head_opt.zero_grad(set_to_none=True)
        loss.backward()
        distributed.mean_gradients(raw.beta_head.parameters(), dist)
        head_opt.step()
        step += 1
        log.bar.update(1)
        if step % c.log_every == 0 or step == total:
            log.log(step, head_opt.param_groups[0]["lr"], {"head_loss": float(loss.detach()), "l1": float(l1),
                                                            "height_waist_cm": float(cm)},
                    {"l1": ("train", "l1"), "cm": ("train", "height_waist_cm")})
        save_if_due(save, step, c.ckpt_every, total, dist)
    return finish(save, log.bar, step, total, dist, log.metrics)


def from_cli(args, cancel=None) -> dict:
    c = T5TrainConfig.load(args.config)
    return train_t5(args.data, args.vae, args.out, c, base_model=args.base_model, resume=args.resume,
                    steps=args.steps, device=args.device, verbose=not args.quiet, cancel=cancel)
