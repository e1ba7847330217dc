"""Train the SA-VAE (stage 1). One file, top to bottom, in the spirit of nanoGPT's train.py.

    train_vae(data="DATA", out="runs/vae", config=SAVAEConfig.small())           # one process
    torchrun --nproc_per_node 2 -m shapemove train vae --data DATA --out RUN     # DDP

Writes into ``out``: ``last.pt`` (full training state, every ``ckpt_every`` steps and at the end,
atomic), ``savae.pt`` (model + metadata, at the end), ``config.json``, ``log.jsonl``.
``resume=True`` continues from ``last.pt`` with the same model, optimizer, scheduler, step and
RNG states, and the data stream is a pure function of the step, so an interrupted and resumed run
ends with the same parameters as an uninterrupted one.
"""
from __future__ import annotations

import copy
import math
import time
from pathlib import Path

import torch
from torch.nn.parallel import DistributedDataParallel as DDP
from torch.utils.data import DataLoader

from ..atomic import atomic_write_json
from ..body.load import load_body_model
from ..body.soles import sole_offsets
from ..errors import ShapeMoveError
from ..models.fsq import codebook_usage
from ..models.savae import SAVAE, SAVAEConfig, TrainSettings, add_residual, load_savae
from ..models.vae_losses import bone_lengths, vae_losses
from . import distributed
from .action_balance import dataset_weights
from .checkpoint_cadence import finish, save_if_due
from .run_log import StepLog
from .checkpoint import config_differences, load_checkpoint, make_metadata, save_checkpoint, stats_hash
from .motion_dataset import BatchStream, MotionClips
from .optimizer_step import optimizer_step
from .resident_batches import ResidentBatches
from .resume import restore, rng_state

KIND = "savae"
RESUME_IGNORES = ("train.steps",)  # a resumed run may be extended; anything else must match


def lr_factor(step: int, t: TrainSettings, total: int) -> float:
    """Multiplier of ``t.lr`` at ``step``: linear warm-up, then step decay or cosine."""
    if step < t.warmup_steps:
        return (step + 1) / t.warmup_steps
    if t.decay == "step":
        return t.gamma ** sum(step >= m * total for m in t.milestones)
    if t.decay == "cosine":
        p = min(1.0, (step - t.warmup_steps) / max(1, total - t.warmup_steps))
        return t.min_lr_ratio + (1 - t.min_lr_ratio) * 0.5 * (1 + math.cos(math.pi * p))
    return 1.0


def resolve_body(body):
    """A BodyModel instance, a body spec ("openbody", an SMPL-family file) or None (the default)."""
    if body is not None and not isinstance(body, str):
        return body

    return load_body_model(body)


def target_bones(body, betas: torch.Tensor) -> torch.Tensor | None:
    """(B, 21) rest bone lengths of ``body`` with ``betas`` (B, 10). Computed on the CPU: the body
    model is a shared cached instance that must stay where it is."""
    with torch.no_grad():
        return bone_lengths(body.rest_joints(betas.detach().cpu())[:, :22]).to(betas.device)


def body_soles(body, betas: torch.Tensor) -> torch.Tensor:
    """(B, 4) sole offsets of joints 7, 8, 10, 11 of ``body`` with ``betas`` (B, 10): the ground
    losses act on the soles of the target body. On the CPU, as ``target_bones``."""
    return sole_offsets(body, betas.detach().cpu()).to(betas.device)


def batch_losses(model_out: dict, b: dict, model, cfg, body) -> dict:
    """``vae_losses`` of one batch: target bones and sole offsets of the batch's bodies (the batch's
    own when it carries them, ``ResidentBatches``), the dataset's stored contacts when it has them,
    its clips' frames alone (``valid``) when short clips are padded (``MotionClips``)."""
    bones = b["bones"] if "bones" in b else target_bones(body, b["betas"])
    soles = b["soles"] if "soles" in b else body_soles(body, b["betas"])
    return vae_losses(model_out["recon"], b["y"], model.mean, model.std, cfg.loss, bones, soles, b.get("contacts"),
                      b.get("valid"))


def start_from(cfg: SAVAEConfig, body_name: str) -> SAVAE:
    """The trained SA-VAE ``cfg.train.init_from`` that a run starts from (fine-tuning), checked to
    have the same network as ``cfg``: only losses and training settings may differ."""
    src = load_savae(cfg.train.init_from, body=body_name)
    theirs, mine = src.cfg.to_dict(), cfg.to_dict()
    # a residual code may be added to a codec that has none (savae.add_residual)
    adds = ("residual_levels", "residual_dropout") if cfg.residual_levels and not src.has_residual else ()
    # a base decoder of another width is trained anew on the source's (frozen or not) codes
    # (not while a residual branch is added: it starts as a copy of the source's base decoder)
    refit = ("decoder_width",) if "decoder" not in cfg.train.freeze and not adds else ()
    diff = config_differences(theirs, mine, ignore=("loss", "train") + adds + refit)
    if diff:
        shown = "; ".join(f"{k}: {theirs.get(k)!r} there, {mine.get(k)!r} here" for k in diff)
        raise ShapeMoveError(f"train.init_from {cfg.train.init_from}: another network ({shown})")
    return src


def freeze(model: SAVAE, parts) -> None:
    """Leave ``parts`` (names of ``savae.PARTS``) as they are: no gradients, so the optimizer skips them.
    With the encoder and quantizer frozen every clip keeps its tokens, so a T5 trained on the
    starting codec's tokens works with the fine-tuned decoder."""
    for name in parts:
        getattr(model, name).requires_grad_(False)


def _to(batch: dict, device) -> dict:
    return {k: v.to(device, non_blocking=True) for k, v in batch.items()}


@torch.no_grad()
def evaluate(model: SAVAE, dataset: MotionClips, cfg: SAVAEConfig, device, body=None) -> dict:
    """Mean losses and codebook usage over up to ``val_batches`` fixed crops of ``dataset``."""
    model.eval()
    bs = cfg.train.batch_size
    keys = [(i, 0) for i in range(len(dataset))][: bs * cfg.train.val_batches]
    sums, n, indices = {}, 0, []
    for k in range(0, len(keys), bs):
        items = [dataset[key] for key in keys[k:k + bs]]
        b = _to({name: torch.stack([it[name] for it in items]) for name in items[0]}, device)
        out = model(b["x"], b["betas"], base=cfg.trains_base)
        losses = batch_losses(out, b, model, cfg, body)
        for name, v in losses.items():
            sums[name] = sums.get(name, 0.0) + float(v) * len(items)
        n += len(items)
        indices.append(out["indices"].reshape(-1))
    model.train()
    if not n:
        return {}
    usage = codebook_usage(torch.cat(indices), model.quantizer.codebook_size)
    return {**{k: v / n for k, v in sums.items()}, "code_usage": usage["used_fraction"], "perplexity": usage["perplexity"]}


def train_vae(data, out, config: SAVAEConfig | None = None, steps: int | None = None, resume: bool = False,
              body=None, device: str | None = None, progress=None, cancel=None, verbose: bool = True,
              init_from=None, minutes: float | None = None) -> dict:
    """Train (or resume) an SA-VAE on the dataset folder ``data``; returns the last metrics.

    progress(fraction, message) is called on rank 0 every ``log_every`` steps; when cancel()
    returns True training stops after saving ``last.pt`` (resume later with resume=True).
    ``minutes``: a time budget for a fresh run; the step count is fitted to it once the first
    ``fitted_steps`` steps are timed (within the warm-up, so the learning-rate schedule never jumps),
    and kept in ``last.pt``: resumed with ``minutes`` (and no ``steps``), the run ends at that count.
    """
    cfg = copy.deepcopy(config) if config is not None else SAVAEConfig.small()
    if steps is not None:
        cfg.train.steps = int(steps)
    if init_from is not None:
        cfg.train.init_from = str(init_from)
    cfg.validate()
    t = cfg.train
    out = Path(out)
    with distributed.process_group(device) as dist:
        return _train(Path(data), out, cfg, t, resume, body, dist, progress, cancel, verbose, minutes, steps)


def fitted_steps(step: int, elapsed: float, per_step: float, minutes: float, t: TrainSettings) -> int:
    """Step count that ends a run within ``minutes`` when ``elapsed`` seconds have gone by at ``step``
    and a step takes ``per_step`` seconds (5 % kept back for validation and checkpoints); never
    below ``step`` + 1 or above ``t.steps``."""
    left = minutes * 60 * 0.95 - elapsed
    return int(min(t.steps, max(step + 1, step + left / max(per_step, 1e-9))))


def _train(data, out, cfg, t, resume, body, dist, progress, cancel, verbose, minutes=None, steps_given=None) -> dict:
    started = time.perf_counter()
    if t.batch_size % dist.world_size:
        raise ShapeMoveError(f"batch_size {t.batch_size} must be divisible by the number of processes ({dist.world_size})")
    body = resolve_body(body)
    body_name = body.name
    source = start_from(cfg, body_name) if t.init_from else None
    # -- data (normalized as the starting model was, when there is one) ----------------------
    stats = (source.mean.numpy(), source.std.numpy()) if source is not None else None
    train_set = MotionClips(data, "train", t.window, seed=t.seed, stats=stats, active_windows=t.active_windows,
                            min_frames=t.min_frames)
    val_set = MotionClips(data, "val", t.window, seed=t.seed + 1, stats=stats, min_frames=t.min_frames)
    mean, std = train_set.mean, train_set.std
    # -- model, optimizer, schedule ----------------------------------------------------------
    torch.manual_seed(t.seed)  # same initial weights on every rank
    model = SAVAE(cfg, mean, std)
    if source is not None and model.has_residual and not source.has_residual:
        add_residual(model, source)
    elif source is not None and source.cfg.base_decoder_width != cfg.base_decoder_width:
        kept = {k: v for k, v in source.state_dict().items() if not k.startswith("decoder.")}
        loaded = model.load_state_dict(kept, strict=False)   # the base decoder starts anew
        other = [k for k in loaded.missing_keys + loaded.unexpected_keys if not k.startswith("decoder.")]
        if other:
            raise ShapeMoveError(f"{t.init_from}: only the base decoder may change width, but these weights do "
                                 f"not match the new codec: {', '.join(other[:5])}")
    elif source is not None:
        model.load_state_dict(source.state_dict())
    freeze(model, t.freeze)
    model = model.to(dist.device)
    trained = [p for p in model.parameters() if p.requires_grad]
    optimizer = torch.optim.AdamW(trained, lr=t.lr, betas=tuple(t.adam_betas), weight_decay=t.weight_decay)
    scheduler = torch.optim.lr_scheduler.LambdaLR(optimizer, lambda s: lr_factor(s, t, t.steps))
    step = 0
    last = out / "last.pt"
    if resume and last.exists():
        ckpt = load_checkpoint(last, map_location="cpu", kind=KIND, body=body_name, config=cfg.to_dict(),
                               ignore=RESUME_IGNORES, stats_hash_=stats_hash(mean, std))
        step = restore(ckpt, model, optimizer, scheduler)
        if minutes and steps_given is None and ckpt.get("total_steps"):
            t.steps = int(ckpt["total_steps"])   # a run fitted to a budget keeps its schedule's length
    elif resume and dist.is_main and verbose:
        print(f"no checkpoint in {out}: starting from scratch")
    raw = model
    if dist.enabled:
        model = DDP(model, device_ids=[dist.device.index] if dist.device.type == "cuda" else None)

    def save(final: bool = False) -> None:
        if not dist.is_main:
            return
        meta = make_metadata(KIND, cfg.to_dict(), body_name, mean, std, step)
        save_checkpoint(last, {"model": raw.state_dict(), "optimizer": optimizer.state_dict(),
                               "scheduler": scheduler.state_dict(), "step": step, "rng": rng_state(),
                               "total_steps": t.steps}, meta)
        if final:
            save_checkpoint(out / "savae.pt", {"model": raw.state_dict()}, meta)

    if dist.is_main:
        atomic_write_json(out / "config.json", cfg.to_dict())
    weights = dataset_weights(train_set.root, train_set.ids, t.action_balance) if t.action_balance > 0 else None
    if t.resident:   # every clip in the device's memory, batches cut there
        batches = ResidentBatches(train_set, t.batch_size // dist.world_size, t.seed, step, weights, dist.device,
                                  dist.rank, body_of=lambda betas: (target_bones(body, betas), body_soles(body, betas)))
    else:
        batches = DataLoader(train_set, batch_sampler=BatchStream(train_set, t.batch_size // dist.world_size, dist.rank,
                                                                  dist.world_size, t.seed, start_step=step,
                                                                  weights=weights),
                             num_workers=t.num_workers, pin_memory=dist.device.type == "cuda")
    batch_iter = iter(batches)
    log = StepLog(out, t.steps, step, dist, progress, "train vae", verbose)
    model.train()
    # a time budget: steps 10 to ``probe`` are timed (the first ones set up kernels and caches)
    probe = max(20, min(200, t.warmup_steps // 2)) if minutes and step == 0 else None
    timed_from = None
    # -- loop ----------------------------------------------------------------------------------
    while step < t.steps:
        if distributed.broadcast_flag(bool(cancel and dist.is_main and cancel()), dist):
            break
        b = _to(next(batch_iter), dist.device)
        result = model(b["x"], b["betas"], base=cfg.trains_base)
        losses = batch_losses(result, b, raw, cfg, body)
        optimizer_step(losses["total"], optimizer, scheduler, trained, t.grad_clip)
        step += 1
        log.bar.update(1)
        if probe and step == 10:
            timed_from = time.perf_counter()
        if step == probe:   # as many steps as fit in the budget (the schedule reads t.steps)
            now = time.perf_counter()
            t.steps = fitted_steps(step, now - started, (now - timed_from) / (probe - 10), minutes, t)
            log.bar.total = t.steps
        done = step == t.steps
        if done or step % t.log_every == 0 or step % t.val_every == 0:
            validate = (lambda: evaluate(raw, val_set, cfg, dist.device, body)) \
                if (done or step % t.val_every == 0) and len(val_set) else None
            log.log(step, scheduler.get_last_lr()[0], {k: float(v.detach()) for k, v in losses.items()},
                    {"loss": ("train", "total"), "val": ("val", "total")}, validate, digits=4)
        save_if_due(save, step, t.ckpt_every, t.steps, dist)
    return finish(save, log.bar, step, t.steps, dist, log.metrics)


def from_cli(args, cancel=None) -> dict:
    """Entry point of `python -m shapemove train vae` (see cli/train.py)."""
    return train_vae(args.data, args.out, SAVAEConfig.load(args.config), steps=args.steps, resume=args.resume,
                     body=args.body, device=args.device, verbose=not args.quiet, init_from=args.init_from,
                     minutes=getattr(args, "minutes", None), cancel=cancel)
