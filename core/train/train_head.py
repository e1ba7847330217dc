"""Train a new `[BETA]` head on an EXISTING exported model, the T5 frozen (issue #25 part 3).

    python -m shapemove train head --data data/built --out runs/head [--model weights/default] [--steps N] [--resume]

The head (``beta_head.TextBetaHead`` by default, writing OpenBody's phenotype sliders + a residual)
reads the T5 decoder's state at `[BETA]`, as the paper's head does, and the frozen MiniLM's token
states of the shape text. Nothing of the T5 moves:
the model folder is copied as it is and only ``t5/beta_head.safetensors`` and ``t5/shapemove.json``
(the head's kind and sizes under ``"beta_head"``) are rewritten, so motions stay bit-identical.

1. examples (``beta_head_refit.HeadExamples.fixed``): ``dataset_examples`` draws of the T5's own
   training examples (captions; the clips' shape texts or none; their betas; a prompt without shape
   text learns the average adult, betas 0, when ``no_shape_average``) and a pool of ``pool`` NEW
   bodies drawn from phenotypes (``synthetic_pool``), each described in people's words and numbers
   beside a random caption; the last ``val_share`` of the pool is held out (logged as ``val``);
2. the frozen T5's `[BETA]` state and the shape text's MiniLM states of every example, computed
   once and cached in ``out/features.pt`` (rebuilt when the model, data or these settings change);
3. the head learns on
   L1(betas) + ``measure_weight`` * (|height| + |waist| error, cm)   (a pool body's L1 reads the betas of
     its drawn sliders, ``l1_from_sliders``: the residual they leave unexplained is in no word; its
     height, waist and mass are still the body's own)
   + ``slider_weight`` * mean |read-back slider - drawn slider| / slider range (gender, age, muscle,
     weight, height read back through OpenBody's map, as ``eval shape-words`` reads them; the drawn
     age in whole years, as the words say it; dataset bodies: their own betas' read-back)
   + ``mass_weight`` * |mass error| (kg, the mesh volume's exact cubic in the betas);
   a head with a unit reader (``"meets": 3``) learns it by cross-entropy on ``label_units``'s labels
   (the units that make each text's numbers add up to its body's own height and mass);
   ``start_from_source`` starts from the source model's head, ``train_only`` names the parts that
   learn (the shipped head's unit reader: ``configs/default_head_units.json``, the rest kept);
4. ``out/last.pt`` every ``ckpt_every`` steps (atomic; ``--resume`` continues from it with the same
   batches); at the end ``out/model/``: the source model folder with the new head and a new manifest.
"""
from __future__ import annotations

import json
import random
import shutil
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import torch

from ..atomic import atomic_path
from ..config_presets import load_config, refuse_unknown
from ..errors import ShapeMoveError
from .warmup_cosine import OptimizerSettings, adamw_warmup_cosine

KIND = "shapemove-head"
FEATURE_KEYS = ("seed", "dataset_examples", "pool", "stated_share", "no_shape_average", "teen_share", "height_margin")
FEATURES_FORMAT = 4   # 3: the shape texts' number features beside their states; 4: stated ages in years


@dataclass
class HeadTrainConfig(OptimizerSettings):
    head: dict = field(default_factory=lambda: {"kind": "text", "hidden": 256, "width": 128, "queries": 4, "heads": 4,
                                                "sliders": 6})  # writes OpenBody's 6 sliders + a residual
    steps: int = 8000
    batch_size: int = 128
    lr: float = 1e-3
    seed: int = 0
    dataset_examples: int = 8000     # draws of the T5's training examples
    pool: int = 24000                # new bodies described in words and numbers
    stated_share: float = 0.4        # share of the pool described by ``stated_text``
    val_share: float = 0.04          # of the pool, held out
    no_shape_average: bool = True    # no shape text -> the average adult (betas 0)
    measure_weight: float = 0.5      # per cm of height + waist error
    slider_weight: float = 10.0      # per unit of mean slider error / slider range
    mass_weight: float = 0.2         # per kg of mass error
    l1_from_sliders: bool = True     # a pool body described in words only: betas L1 against its drawn sliders' betas
    teen_weight: float = 4.0         # pool bodies under 20 drawn this many times as often (3 % of the ages drawn)
    teen_share: float = 0.0          # share of the pool drawn as teenagers, 14-19 (phenotype_sample.TEEN_AGES)
    height_margin: float = 0.0       # the pool's height slider drawn this fraction of its range past each end
    start_from_source: bool = False  # the new head starts from the source model's own head (every weight it has)
    train_only: list = field(default_factory=list)   # names of the parts that learn (e.g. ["units"]); [] = all
    log_every: int = 100
    ckpt_every: int = 500

    @classmethod
    def tiny(cls) -> "HeadTrainConfig":
        return cls(head={"kind": "text", "hidden": 32, "width": 32, "queries": 2, "heads": 2, "sliders": 6}, steps=12,
                   batch_size=16,
                   warmup_steps=2, dataset_examples=24, pool=40, val_share=0.1, log_every=4, ckpt_every=4)

    @classmethod
    def load(cls, name_or_path: str | None) -> "HeadTrainConfig":
        def from_json(data, p):
            refuse_unknown(data, asdict(cls()), p, "head config")
            return cls(**data)

        return load_config("head", name_or_path, {"tiny": cls.tiny, "small": cls, "paper": cls}, from_json)

    def validate(self) -> None:
        if self.steps < 1 or self.batch_size < 1 or self.dataset_examples < 0 or self.pool < 0:
            raise ShapeMoveError("head config: steps and batch_size must be >= 1, dataset_examples and pool >= 0")
        if self.dataset_examples + self.pool < 2:
            raise ShapeMoveError("head config: dataset_examples + pool must give at least 2 examples")
        if not 0 <= self.stated_share <= 1 or not 0 <= self.val_share < 1 or not 0 <= self.teen_share <= 1:
            raise ShapeMoveError("head config: stated_share and teen_share must be in [0, 1] and val_share in [0, 1)")
        if not 0 <= self.height_margin <= 0.5:
            raise ShapeMoveError("head config: height_margin must be in [0, 0.5]")
        if self.lr <= 0 or min(self.measure_weight, self.slider_weight, self.mass_weight) < 0 or self.teen_weight <= 0:
            raise ShapeMoveError("head config: lr > 0, non-negative loss weights and teen_weight > 0 are required")
        if not isinstance(self.train_only, list) or not all(isinstance(t, str) and t for t in self.train_only):
            raise ShapeMoveError(f"head config: train_only must be a list of part names, got {self.train_only!r}")
        if not isinstance(self.head, dict) or self.head.get("kind") not in ("mlp", "text"):
            raise ShapeMoveError(f"head config: head must be {{\"kind\": \"text\" | \"mlp\", ...sizes}}, got {self.head!r}")


# -- features: the frozen model's reading of every example, computed once ----------------------------
class Features:
    """Per example: the `[BETA]` state (N, d), the shape text's MiniLM states and its tokens' number
    features (``text_numbers``; each stored as one float16 block, rows ``offsets[i]:offsets[i+1]``,
    none for no shape text; held padded to the longest), betas (N, 10), phenotype targets (N, P),
    pool flag (N,)."""

    def __init__(self, d: dict):
        self.h, self.betas, self.pheno, self.pool = d["h"], d["betas"], d["pheno"], d["pool"]
        self.numbers = torch.tensor([any(ch.isdigit() for ch in t) for t in d["texts"]])  # the text states sizes
        offsets = d["offsets"]
        self.lens = offsets[1:] - offsets[:-1]
        L = max(1, int(self.lens.max()))
        self.padded = torch.zeros(len(self.lens), L, d["states"].shape[1], dtype=torch.float16)
        self.padded_numbers = torch.zeros(len(self.lens), L, d["numbers"].shape[1], dtype=torch.float16)
        for i, (o, n) in enumerate(zip(offsets[:-1].tolist(), self.lens.tolist())):
            self.padded[i, :n] = d["states"][o:o + n]
            self.padded_numbers[i, :n] = d["numbers"][o:o + n]

    def __len__(self) -> int:
        return len(self.h)

    def batch(self, idx) -> tuple:
        """(states at [BETA], shape text states (B, L, 384), their mask, their number features (B, L, F),
        betas, phenotype targets)."""
        idx = torch.as_tensor(idx, dtype=torch.long)
        n = self.lens[idx]
        L = max(1, int(n.max()))
        return (self.h[idx], self.padded[idx, :L].float(), torch.arange(L)[None] < n[:, None],
                self.padded_numbers[idx, :L].float(), self.betas[idx], self.pheno[idx])

    def bins(self, idx, size: int) -> list:
        """``idx`` sorted by text length and cut into runs of about ``size``: a batch drawn from one
        run pads little (texts run from 0 to ~55 tokens)."""
        idx = torch.as_tensor(idx, dtype=torch.long)
        order = idx[torch.argsort(self.lens[idx], stable=True)]
        k = max(1, len(order) // max(1, size))
        return [b for b in torch.tensor_split(order, k) if len(b)]


@torch.no_grad()
def build_features(t5, reader, examples, readback, c: HeadTrainConfig, progress: bool) -> dict:
    from tqdm import tqdm

    from ..models.text_encoder import StateCache

    rng = random.Random(c.seed)
    motions, shapes, betas, pool, pheno = examples.fixed(rng, c.dataset_examples)
    if c.no_shape_average:  # no words about the body: the average adult
        none = torch.tensor([s is None or not str(s).strip() for s in shapes])
        betas = betas.clone()
        betas[none] = 0.0
    pheno = torch.as_tensor(pheno, dtype=torch.float32)
    own = readback.sliders(betas)            # dataset bodies: their own betas' read-back
    if pheno.shape[1] == 0:
        pheno = own
    else:
        pheno = torch.where(torch.isnan(pheno), own, pheno)
        age = readback.names.index("age")
        pheno[:, age] = torch.where(torch.as_tensor(pool), pheno[:, age].floor(), pheno[:, age])  # whole years
    cache = StateCache(reader)
    cache.add([m for m in motions] + [s for s in shapes if s], progress=progress)
    from ..models.text_numbers import FEATURES, number_features

    hs, blocks, lens, numbers = [], [], [], []
    bar = tqdm(total=len(motions), desc="read examples", unit="ex", disable=not progress)
    for s in range(0, len(motions), 128):
        m, sh = motions[s:s + 128], shapes[s:s + 128]
        hs.append(t5.beta_state(t5.inputs_for(cache, m, sh)))
        bar.update(len(m))
    bar.close()
    said = [str(sh) for sh in shapes if sh and str(sh).strip()]
    values = iter(number_features(cache.encoder.tokenizer, said))   # one per said text, in order
    for sh in shapes:
        if sh and str(sh).strip():
            x, f = cache.states_of[str(sh)], next(values)
        else:
            x, f = torch.zeros(0, cache.encoder.dim, dtype=torch.float16), torch.zeros(0, FEATURES)
        if len(f) != len(x):
            raise ShapeMoveError(f"shape text {sh!r}: {len(x)} token states but {len(f)} tokens")
        blocks.append(x)
        numbers.append(f.to(torch.float16))
        lens.append(len(x))
    offsets = torch.zeros(len(lens) + 1, dtype=torch.long)
    offsets[1:] = torch.as_tensor(lens).cumsum(0)
    return {"h": torch.cat(hs), "states": torch.cat(blocks), "numbers": torch.cat(numbers), "offsets": offsets,
            "betas": betas, "pheno": pheno, "pool": torch.as_tensor(pool), "texts": [s or "" for s in shapes], "motions": motions}


def _stamp(model_dir: Path, data: Path, c: HeadTrainConfig) -> str:
    from ..model_files import sha256_file

    t5 = model_dir / "t5"
    return json.dumps({"format": FEATURES_FORMAT, "t5": sha256_file(t5 / "model.safetensors"),
                       "config": (t5 / "config.json").read_text(), "data": str(data.resolve()),
                       **{k: getattr(c, k) for k in FEATURE_KEYS}}, sort_keys=True)


def load_features(out: Path, stamp: str, make) -> Features:
    path = out / "features.pt"
    if path.is_file():
        try:
            d = torch.load(path, map_location="cpu", weights_only=True)
            if d.get("stamp") == stamp:
                return Features(d)
        except Exception:  # a damaged cache is rebuilt, never used
            pass
    d = make()
    with atomic_path(path) as tmp:
        torch.save({**d, "stamp": stamp}, tmp)
    return Features(d)


# -- the model folder with the new head ------------------------------------------------------------
def export_model(src: Path, dst: Path, head, meta: dict) -> Path:
    """``src`` (a model folder) copied to ``dst`` with ``head`` in ``t5/beta_head.safetensors``, its
    kind/sizes and ``meta`` in ``t5/shapemove.json`` and one new manifest. Atomic (``dst.tmp`` renamed)."""
    from safetensors.torch import save_file

    from ..model_files import write_manifest

    tmp = dst.with_name(dst.name + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    shutil.copytree(src, tmp, ignore=shutil.ignore_patterns("*.tmp", "*.partial", "*.lock"))
    save_file({k: v.detach().float().contiguous() for k, v in head.state_dict().items()},
              str(tmp / "t5" / "beta_head.safetensors"))
    info = json.loads((tmp / "t5" / "shapemove.json").read_text())
    info["beta_head"] = head.config()
    info["beta_head_training"] = meta
    (tmp / "t5" / "shapemove.json").write_text(json.dumps(info, indent=2, default=str))
    write_manifest(tmp)
    old = dst.with_name(dst.name + ".old")
    shutil.rmtree(old, ignore_errors=True)
    if dst.exists():
        dst.rename(old)
    tmp.rename(dst)
    shutil.rmtree(old, ignore_errors=True)
    return dst


# -- training --------------------------------------------------------------------------------------
def start_from(head, source, where) -> None:
    """``head`` takes every weight of ``source`` (the model's own head); its parts that ``source``
    lacks (a unit reader, say) keep their new values. Refused where a shared weight's shape differs."""
    own, theirs = head.state_dict(), source.state_dict()
    wrong = [k for k in theirs if k not in own or own[k].shape != theirs[k].shape]
    if wrong:
        raise ShapeMoveError(f"start_from_source: the head of {where} does not fit the new head's sizes "
                             f"({', '.join(wrong[:4])}{' ...' if len(wrong) > 4 else ''}); match its sizes in \"head\"")
    head.load_state_dict({**own, **theirs})


def label_units(feats: Features, measure, mass) -> torch.Tensor:
    """(N, L) the unit index of each number's first word piece in every example's shape text
    (``number_units.unit_labels``, from the example's own height and mass), -100 elsewhere."""
    from ..models.number_units import number_starts, unit_labels

    labels = torch.full(feats.padded_numbers.shape[:2], -100, dtype=torch.long)
    with torch.no_grad():
        height = torch.cat([measure(b)[:, 0] for b in feats.betas.split(4096)]).tolist()
        kg = torch.cat([mass(b) for b in feats.betas.split(4096)]).tolist()
    for i in torch.nonzero(feats.numbers).flatten().tolist():
        start, value = number_starts(feats.padded_numbers[i:i + 1, :int(feats.lens[i])].float())
        where = torch.nonzero(start[0]).flatten()
        if len(where):
            labels[i, where] = torch.tensor(unit_labels(value[0, where].tolist(), height[i], kg[i]))
    return labels


def trainable(head, parts: list) -> list:
    """The parameters that learn: all, or those of the named parts (``head.<part>``); the rest frozen."""
    if not parts:
        return list(head.parameters())
    names = dict(head.named_children())
    missing = [p for p in parts if p not in names]
    if missing:
        raise ShapeMoveError(f"train_only: the head has no part {', '.join(missing)} (it has {', '.join(names)})")
    for p in head.parameters():
        p.requires_grad_(False)
    learn = [p for part in parts for p in names[part].parameters()]
    for p in learn:
        p.requires_grad_(True)
    return learn


def _metrics(head, feats: Features, idx, readback, measure) -> dict:
    """Held-out pool bodies: betas L1, height/waist/mass errors, slider errors, gender right."""
    with torch.no_grad():
        h, text, mask, numbers, betas, pheno = feats.batch(idx)
        head.refusing = False   # a head still learning may read impossible sizes: measured, not refused
        try:
            pred = head(h, text, mask, *((numbers,) if getattr(head, "reads_numbers", False) else ()))
        finally:
            head.refusing = True
        dm = (measure(pred) - measure(betas)).abs().mean(0)
        kg = (readback.mass(pred) - readback.mass(betas)).abs().mean()
        sl = readback.sliders(pred)
        lo, hi = (torch.as_tensor(readback.ranges[:, i], dtype=torch.float32) for i in (0, 1))
        sl = torch.minimum(torch.maximum(sl, lo), hi)
        g, a, m = (readback.names.index(n) for n in ("gender", "age", "muscle"))
        sex = (pheno[:, g] <= 0.25) | (pheno[:, g] >= 0.75)
        right = ((sl[:, g] <= 0.25) == (pheno[:, g] <= 0.25)) & ((sl[:, g] >= 0.75) == (pheno[:, g] >= 0.75))
        return {"l1": float((pred - betas).abs().mean()), "height_cm": float(dm[0]), "waist_cm": float(dm[1]),
                "kg": float(kg), "age_y": float((sl[:, a] - pheno[:, a]).abs().mean()),
                "muscle": float((sl[:, m] - pheno[:, m]).abs().mean()),
                "gender_right_pct": 100 * float(right[sex].float().mean()) if sex.any() else float("nan")}


def train_head(model_dir, data, out, config: HeadTrainConfig | None = None, resume: bool = False,
               steps: int | None = None, progress=None, cancel=None, verbose: bool = True) -> dict:
    from ..body.load import load_body_model
    from ..generation.model_bundle import model_files, resolve_model_dir
    from ..models.beta_head import build_head
    from ..models.shapemove_t5 import ShapeMoveT5
    from .beta_head_refit import HeadExamples, Readback, head_loss
    from .checkpoint import config_differences, load_checkpoint, save_checkpoint
    from .checkpoint_cadence import finish, save_if_due
    from .distributed import DistInfo
    from .motion_dataset import read_split
    from .optimizer_step import optimizer_step
    from .resume import restore, rng_state
    from .run_log import StepLog
    from .t5_dataset import T2MExamples

    c = config or HeadTrainConfig()
    if steps is not None:
        c.steps = int(steps)
    c.validate()
    model_dir, data, out = resolve_model_dir(model_dir), Path(data), Path(out)
    t5_dir = model_files(model_dir)["t5"]
    if not (t5_dir / "shapemove.json").is_file():
        raise ShapeMoveError(f"{model_dir} has no t5/ model: the [BETA] head lives there")
    if not data.is_dir():
        raise ShapeMoveError(f"dataset folder not found: {data}")
    if out.resolve() == model_dir.resolve() or model_dir.resolve() in out.resolve().parents:
        raise ShapeMoveError(f"--out {out} lies inside the source model folder {model_dir}; pick another folder")
    t5, reader = ShapeMoveT5.load(t5_dir)
    if t5.encoder_kind != "minilm":
        raise ShapeMoveError(f"{t5_dir}: `train head` needs a model whose T5 reads MiniLM states "
                             f"(this one: {t5.encoder_kind})")
    out.mkdir(parents=True, exist_ok=True)

    ids = read_split(data, "train")
    if not ids:
        raise ShapeMoveError(f"{data}: no training clips (train.txt missing or empty): build the dataset with `data build`")
    # the head reads no motion codes: every training clip takes part (T2MExamples wants tokens)
    train_set = T2MExamples(data, "train", {cid: np.zeros(1, np.int16) for cid in ids}, max_codes=1)
    examples = HeadExamples(train_set, t5.info.get("vae_body"), c.seed, c.pool, c.stated_share, c.teen_share,
                            c.height_margin)
    readback = Readback(examples.body)
    torch.manual_seed(c.seed)
    head = build_head(c.head, t5.d_model, getattr(examples.body, "phenotype_map", None),
                      readback.size_model() if c.head.get("meets") else None)
    if c.start_from_source:
        start_from(head, t5.beta_head, t5_dir)
    learn = trainable(head, c.train_only)
    feats = load_features(out, _stamp(model_dir, data, c),
                          lambda: build_features(t5, reader, examples, readback, c, verbose))
    n = len(feats)
    pool_idx = torch.nonzero(feats.pool).flatten()
    n_val = int(round(len(pool_idx) * c.val_share))
    val_idx = pool_idx[len(pool_idx) - n_val:] if n_val else pool_idx[:0]
    train_idx = torch.as_tensor(sorted(set(range(n)) - set(val_idx.tolist())), dtype=torch.long)

    units = label_units(feats, examples.measure, readback.mass) if c.head.get("meets") == 3 else None
    optimizer, scheduler = adamw_warmup_cosine(learn, c)
    step, rng = 0, random.Random(c.seed + 1)
    last = out / "last.pt"
    if resume and last.is_file():
        ckpt = load_checkpoint(last, kind=KIND)
        diff = config_differences({**asdict(HeadTrainConfig()), **ckpt["config"]}, asdict(c), ignore=("steps",))
        if diff:
            raise ShapeMoveError(f"{last}: cannot resume, the configuration differs ({', '.join(diff)})")
        if ckpt.get("source_t5") != _stamp(model_dir, data, c):
            raise ShapeMoveError(f"{last}: this run trained a head for another model or dataset; use another --out")
        step = restore(ckpt, head, optimizer, scheduler, weights_key="head")
        rng.setstate((3, tuple(ckpt["py_rng"]), None))
    meta = {"source": str(model_dir), "data": str(data), "config": asdict(c)}

    def save(final: bool = False):
        st = rng.getstate()
        save_checkpoint(last, {"kind": KIND, "config": asdict(c), "head": head.state_dict(),
                               "optimizer": optimizer.state_dict(), "scheduler": scheduler.state_dict(),
                               "step": step, "rng": rng_state(), "py_rng": list(st[1]),
                               "source_t5": _stamp(model_dir, data, c)},
                        {"format": 1, "kind": KIND})
        if final:
            export_model(model_dir, out / "model", head, meta | {"step": step})

    dist = DistInfo()
    log = StepLog(out, c.steps, step, dist, progress, "train head", verbose)
    extra_parts: dict = {}

    def extra(pred, pheno, betas):
        loss, parts = readback.loss(pred, pheno, betas, c.slider_weight, c.mass_weight)
        extra_parts.update(parts)
        return loss

    age = readback.names.index("age")
    often = torch.where(feats.pool & (feats.pheno[:, age] < 20), c.teen_weight, 1.0)
    bins = feats.bins(train_idx, 4 * c.batch_size)  # a batch: examples of one length bin
    weights = [float(often[b].sum()) for b in bins]
    cum = [often[b].cumsum(0).tolist() for b in bins]
    head.train()
    while step < c.steps:
        if cancel and cancel():
            break
        k = rng.choices(range(len(bins)), weights)[0]
        pick = bins[k][torch.as_tensor(rng.choices(range(len(bins[k])), cum_weights=cum[k], k=c.batch_size))]
        h, text, mask, numbers, betas, pheno = feats.batch(pick)
        target = None
        if c.l1_from_sliders and pheno.shape[1]:  # words only: the body the words describe (the residual the
            words = feats.pool[pick] & ~feats.numbers[pick]  # sliders leave is in no word); numbers: the body itself
            target = torch.where(words[:, None], readback.to_betas(pheno), betas)
        loss, l1, cm = head_loss(head, h, betas, examples.measure, c.measure_weight, text, mask,
                                 extra=lambda pred: extra(pred, pheno, betas), l1_target=target, numbers=numbers,
                                 mass=readback.mass, mass_weight=c.mass_weight,
                                 units=None if units is None else units[pick])
        if loss.requires_grad:   # a batch of words alone has nothing for a unit reader trained alone
            optimizer_step(loss, optimizer, scheduler, learn, c.grad_clip)
        else:
            scheduler.step()
        step += 1
        log.bar.update(1)
        if step % c.log_every == 0 or step == c.steps:
            head.eval()
            log.log(step, scheduler.get_last_lr()[0],
                    {"loss": float(loss.detach()), "l1": float(l1), "height_waist_cm": float(cm), **extra_parts},
                    {"loss": ("train", "loss"), "cm": ("train", "height_waist_cm"), "kg": ("train", "kg")},
                    validate=(lambda: _metrics(head, feats, val_idx, readback, examples.measure)) if n_val else None)
            head.train()
        save_if_due(save, step, c.ckpt_every, c.steps, dist)
    head.eval()
    return finish(save, log.bar, step, c.steps, dist, log.metrics)


def from_cli(args, cancel=None) -> dict:
    c = HeadTrainConfig.load(args.config)
    res = train_head(args.model, args.data, args.out, c, resume=args.resume, steps=args.steps,
                     verbose=not args.quiet, cancel=cancel)
    if (Path(args.out) / "model").is_dir() and res.get("step", 0) >= c.steps:
        res["model"] = str(Path(args.out) / "model")
    return res
