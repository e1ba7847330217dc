"""Text-motion retrieval metrics on TMA embeddings: R-precision, matching score, FID.

As in the HumanML3D/T2M protocol: the set is cut into groups of ``group`` (32) pairs; within a
group each text ranks all motions by distance and R-precision@k is the share of texts whose own
motion is in the top k. Matching score = mean distance between paired embeddings. FID is the
Fréchet distance between the Gaussian fits of two sets of motion embeddings.
"""
from __future__ import annotations

import numpy as np
from scipy import linalg


def r_precision(text_emb: np.ndarray, motion_emb: np.ndarray, top_k=(1, 2, 3), group: int = 32,
                seed: int = 0) -> dict:
    n = len(text_emb)
    if n < 2:
        raise ValueError("R-precision needs at least two pairs")
    order = np.random.default_rng(seed).permutation(n)
    hits = {k: 0 for k in top_k}
    counted = 0
    for s in range(0, n, group):
        idx = order[s: s + group]
        if len(idx) < 2:
            continue
        d = np.linalg.norm(text_emb[idx, None] - motion_emb[None, idx], axis=-1)
        rank = (d < np.diag(d)[:, None]).sum(1)  # motions strictly closer than the true one
        for k in top_k:
            hits[k] += int((rank < k).sum())
        counted += len(idx)
    return {f"top{k}": hits[k] / counted for k in top_k} | {"group": min(group, n)}


def matching_score(text_emb: np.ndarray, motion_emb: np.ndarray) -> float:
    return float(np.linalg.norm(text_emb - motion_emb, axis=-1).mean())


def fid(a: np.ndarray, b: np.ndarray) -> float:
    """Fréchet distance between Gaussians fitted to the rows of ``a`` and ``b``."""
    mu1, mu2 = a.mean(0), b.mean(0)
    s1, s2 = np.cov(a, rowvar=False), np.cov(b, rowvar=False)
    covmean = linalg.sqrtm(s1 @ s2)
    if np.iscomplexobj(covmean):
        covmean = covmean.real
    return float(((mu1 - mu2) ** 2).sum() + np.trace(s1 + s2 - 2 * covmean))
