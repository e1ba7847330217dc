"""Scoring with a trained TMA: R-precision and matching score of paired motions and captions, and
the real data's scores (the ceiling that generated motions are compared against).

Loading and embedding live beside the model (``core/models/tma_embed.py``); they are re-exported
here for the evaluation modules and older callers.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from ..models.tma_embed import (  # noqa: F401  (re-exported)
    FEATURE_DIM, KIND, check_features, embed_motions, embed_texts, load_tma, pad_batch, text_inputs, tma_path,
    windows)


def eval_pairs(root, ids: list[str], kind: str = "new_joint_vecs", seed: int = 0) -> tuple[list, list[str]]:
    """Features and one caption per clip (chosen with a fixed seed) of the clips ``ids``."""
    from ..train.t5_dataset import read_lines

    root = Path(root)
    rng = np.random.default_rng(seed)
    feats, texts = [], []
    for cid in ids:
        caps = read_lines(root / "texts" / f"{cid}.txt")
        f = root / kind / f"{cid}.npy"
        if not caps or not f.is_file():
            continue
        feats.append(np.load(f).astype(np.float32))
        texts.append(caps[int(rng.integers(len(caps)))])
    return feats, texts


def score_pairs(model, tok, mean, std, feats: list, texts: list[str]) -> dict:
    """R-precision top1/top3 (groups of 32) and matching score of paired motions/texts."""
    from .retrieval import matching_score, r_precision

    t = embed_texts(model, tok, texts)
    m = embed_motions(model, feats, mean, std)
    r = r_precision(t, m, top_k=(1, 3))
    return {"r_precision_top1": r["top1"], "r_precision_top3": r["top3"], "matching_score": matching_score(t, m),
            "clips": len(feats)}


def real_motion_scores(data, split: str = "test", tma=None, kind: str = "new_joint_vecs") -> dict:
    """R-precision/matching score of the real clips of ``split`` against their own captions:
    the ceiling for generated motions. ``tma``: a path or a ``load_tma`` tuple."""
    from ..train.motion_dataset import read_split

    if tma is None:
        raise ShapeMoveError("real_motion_scores needs a TMA (path to tma.pt or a load_tma() result)")
    model, tok, mean, std = load_tma(tma) if isinstance(tma, (str, Path)) else tma
    data = Path(data)
    if not data.is_dir():
        raise ShapeMoveError(f"dataset folder not found: {data}")
    ids = read_split(data, split)
    feats, texts = eval_pairs(data, ids, kind)
    if len(feats) < 2:
        raise ShapeMoveError(f"{data}: split '{split}' has {len(feats)} clip(s) with features and captions; need 2")
    return score_pairs(model, tok, mean, std, feats, texts)
