"""Using a trained TMA: load it, embed texts and motions. What the product (best-of-N choice in
``core/generation/rerank.py``, library search in ``core/search/``) and the evaluation
(``core/eval/tma_embed.py``: R-precision, FID, the real data's ceiling) both need, beside the model.

A TMA run folder holds ``tma.pt`` (weights + metadata with the data's Mean/Std and the sha256 of
the pretrained text encoder it reads: ``core/models/text_encoder.py``). TMAs trained before the
pretrained encoder keep a sentencepiece ``tokenizer/`` beside ``tma.pt`` and still load. What
``load_tma`` returns as the "tokenizer" is whatever turns texts into the text side's inputs: the
frozen MiniLM, or that sentencepiece tokenizer (``text_inputs``). Motions are raw (T,263) HumanML3D features; they are normalized with the
TMA's own Mean/Std. A motion longer than the model's ``max_frames`` is embedded as the mean of
evenly spaced ``max_frames`` windows (re-normalized), the same crops the model was trained on.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from ..errors import ShapeMoveError
from .tma import TMA, TMAConfig

KIND = "tma"
FEATURE_DIM = 263


def tma_path(path) -> Path:
    """``tma.pt`` itself, or a folder holding it (a run folder, a model folder's ``tma/``)."""
    p = Path(path)
    if p.is_dir():
        for cand in (p / "tma.pt", p / "tma" / "tma.pt"):
            if cand.is_file():
                return cand
        raise ShapeMoveError(f"{p}: no tma.pt in this folder (train one with `python -m shapemove train tma`)")
    return p


def load_tma(path):
    """(model in eval mode, text reader, mean (263,), std (263,)) from ``tma.pt`` (or its folder).
    A checkpoint of another kind, one trained on another text encoder, or an old one without its
    ``tokenizer/`` folder, is a ShapeMoveError."""
    from ..train.checkpoint import load_checkpoint

    path = tma_path(path)
    ckpt = load_checkpoint(path, kind=KIND)
    meta = ckpt["metadata"]
    try:
        model_cfg = dict(meta["config"]["model"])
        model_cfg.setdefault("text_encoder", "sentencepiece")  # checkpoints from before the pretrained encoder
        cfg = TMAConfig(**model_cfg)
    except (KeyError, TypeError) as exc:
        raise ShapeMoveError(f"{path}: TMA checkpoint without a valid model config ({exc})") from exc
    if cfg.text_encoder == "minilm":
        from .text_encoder import check_fingerprint, load_text_encoder

        check_fingerprint(meta.get("text_encoder"), str(path))
        tok = load_text_encoder()
    elif cfg.text_encoder == "sentencepiece":
        from .tokenizer import load_tokenizer

        tok_dir = path.parent / "tokenizer"
        if not (tok_dir / "tokenizer.json").is_file():
            raise ShapeMoveError(f"{path}: its tokenizer is missing ({tok_dir}/tokenizer.json); keep tokenizer/ beside tma.pt")
        tok = load_tokenizer(tok_dir)
        if len(tok) != cfg.vocab_size:
            raise ShapeMoveError(f"{path}: tokenizer in {tok_dir} has {len(tok)} tokens, the model expects {cfg.vocab_size}")
    else:
        raise ShapeMoveError(f"{path}: unknown TMA text encoder {cfg.text_encoder!r}")
    model = TMA(cfg)
    model.load_state_dict(ckpt["model"])
    model.eval()
    mean = np.asarray(meta["mean"], np.float32)
    std = np.asarray(meta["std"], np.float32)
    return model, tok, mean, std


def text_inputs(model: TMA, tok, texts: list[str]) -> tuple[torch.Tensor, torch.Tensor]:
    """What ``model.text`` reads for ``texts``: MiniLM token states + mask (``tok`` a TextEncoder or
    StateCache), or sentencepiece ids + mask (old models)."""
    if model.cfg.text_encoder == "minilm":
        x, m = tok.states(texts)
        return x[:, : model.cfg.max_text], m[:, : model.cfg.max_text]
    enc = tok(texts, return_tensors="pt", padding=True, truncation=True, max_length=model.cfg.max_text)
    return enc.input_ids, enc.attention_mask


def _device(model) -> torch.device:
    return next(model.parameters()).device


@torch.no_grad()
def embed_texts(model: TMA, tok, texts: list[str], batch: int = 128) -> np.ndarray:
    """(N, E) unit vectors for ``texts`` (float32)."""
    texts = [str(t) for t in texts]
    if not texts:
        return np.zeros((0, model.cfg.embed), np.float32)
    was_training = model.training
    model.eval()
    out = []
    for s in range(0, len(texts), batch):
        a, b = text_inputs(model, tok, texts[s:s + batch])
        out.append(model.text(a.to(_device(model)), b.to(_device(model))).cpu())
    model.train(was_training)
    return torch.cat(out).numpy().astype(np.float32)


def windows(length: int, max_frames: int) -> list[tuple[int, int]]:
    """(start, stop) of the evenly spaced ``max_frames`` windows covering ``length`` frames."""
    if length <= max_frames:
        return [(0, length)]
    n = -(-length // max_frames)
    starts = np.linspace(0, length - max_frames, n).round().astype(int)
    return [(int(s), int(s) + max_frames) for s in starts]


def check_features(feats, name: str = "motion") -> np.ndarray:
    f = np.asarray(feats, dtype=np.float32)
    if f.ndim != 2 or f.shape[1] != FEATURE_DIM:
        raise ShapeMoveError(f"{name}: features must be (frames, {FEATURE_DIM}), got shape {f.shape}")
    if len(f) < 4:
        raise ShapeMoveError(f"{name}: too short to embed ({len(f)} frames, need at least 4)")
    if not np.isfinite(f).all():
        raise ShapeMoveError(f"{name}: features contain NaN or inf")
    return f


@torch.no_grad()
def embed_motions(model: TMA, feats: list, mean, std, batch: int = 64) -> np.ndarray:
    """(N, E) unit vectors for a list of raw (T_i, 263) feature arrays (float32)."""
    if not len(feats):
        return np.zeros((0, model.cfg.embed), np.float32)
    mean, std = np.asarray(mean, np.float32), np.asarray(std, np.float32)
    crops, owner = [], []
    for i, f in enumerate(feats):
        f = (check_features(f, f"motion {i}") - mean) / std
        for a, b in windows(len(f), model.cfg.max_frames):
            crops.append(f[a:b])
            owner.append(i)
    was_training = model.training
    model.eval()
    dev = _device(model)
    order = np.argsort([len(c) for c in crops], kind="stable")  # similar lengths together: less padding
    emb = np.zeros((len(crops), model.cfg.embed), np.float32)
    for s in range(0, len(order), batch):
        idx = order[s:s + batch]
        x, lengths = pad_batch([crops[k] for k in idx])
        emb[idx] = model.motion(x.to(dev), lengths.to(dev)).cpu().numpy()
    model.train(was_training)
    out = np.zeros((len(feats), model.cfg.embed), np.float32)
    np.add.at(out, np.asarray(owner), emb)
    return out / np.linalg.norm(out, axis=1, keepdims=True).clip(1e-8)


def pad_batch(crops: list[np.ndarray]) -> tuple[torch.Tensor, torch.Tensor]:
    """Zero-padded (B, T_max, D) float32 tensor and the (B,) lengths."""
    lengths = torch.tensor([len(c) for c in crops])
    x = torch.zeros(len(crops), int(lengths.max()), crops[0].shape[1])
    for k, c in enumerate(crops):
        x[k, : len(c)] = torch.as_tensor(c)
    return x, lengths
