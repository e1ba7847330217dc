"""New bodies drawn as people are described: phenotypes (gender, age, muscle, weight, height,
proportions) sampled over OpenBody's slider ranges, mapped to betas by the shipped phenotype map,
plus the part of the betas the sliders do not explain (a residual scaled by ``1 - r2`` per beta).

Used by the dataset builder's shape augmentation and by the `[BETA]` head's pool of new bodies, so
that the bodies the model learns from span men and women, young and old, lean and heavy, and each
comes with the phenotype that describes it in words (``core.data.phenotype_captions.phenotype_texts``;
``core.text.shape_words`` reads such words back).
"""
from __future__ import annotations

import numpy as np

RESIDUAL_SCALE = 0.6  # of sqrt(1 - r2): the variation the sliders leave unexplained, kept but damped
BETA_CLIP = 3.0


TEEN_AGES = (14.0, 20.0)  # years: the parser's teenagers (13-19, "teenage" 16), the map extrapolated below its 18


def sample_phenotypes(pmap, rng: np.random.Generator, n: int, teen_share: float = 0.0,
                      height_margin: float = 0.0) -> np.ndarray:
    """(n, P) slider values: gender near 0 or near 1 for 90 % (men and women), age uniform over the
    range, the others uniform over their ranges (proportions over the middle half).

    ``teen_share``: that share of the bodies are teenagers, aged over ``TEEN_AGES`` (below the map's
    18 the map is extrapolated, as the parser does for "teenage"); ``height_margin``: the height
    slider is drawn that fraction of its range beyond each end, so that a tall woman and a short man
    (who the map's range barely holds) are drawn too. Both 0 (the dataset builder): as before."""
    names = list(pmap.names)
    lo, hi = pmap.ranges[:, 0].copy(), pmap.ranges[:, 1].copy()
    if height_margin and "height" in names:
        j = names.index("height")
        lo[j], hi[j] = lo[j] - height_margin * (hi[j] - lo[j]), hi[j] + height_margin * (hi[j] - lo[j])
    p = lo + (hi - lo) * rng.random((n, len(names)))
    if teen_share and "age" in names:
        teen = rng.random(n) < teen_share
        p[teen, names.index("age")] = rng.uniform(*TEEN_AGES, int(teen.sum()))
    if "gender" in names:
        g = names.index("gender")
        kind = rng.random(n)
        p[:, g] = np.where(kind < 0.45, rng.uniform(0.0, 0.12, n),
                           np.where(kind < 0.9, rng.uniform(0.88, 1.0, n), rng.uniform(0.0, 1.0, n)))
    if "proportions" in names:
        j = names.index("proportions")
        p[:, j] = rng.uniform(0.3, 0.7, n)
    return p


def betas_for_phenotypes(pmap, phenotypes: np.ndarray, rng: np.random.Generator | None, r2=None) -> np.ndarray:
    """(n, P) sliders -> (n, 10) float32 betas; with ``rng`` and ``r2`` (per-beta R² of the map) a
    residual N(0, RESIDUAL_SCALE * sqrt(1 - r2)) is added."""
    b = pmap.to_betas(np.asarray(phenotypes, dtype=np.float64))
    if rng is not None and r2 is not None:
        sd = RESIDUAL_SCALE * np.sqrt(np.clip(1.0 - np.asarray(r2, np.float64), 0.0, 1.0))
        b = b + rng.standard_normal(b.shape) * sd
    return np.clip(b, -BETA_CLIP, BETA_CLIP).astype(np.float32)


def sample_bodies(pmap, seed: int, n: int, r2=None, teen_share: float = 0.0,
                  height_margin: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(phenotypes (n, P), betas (n, 10)): ``n`` new bodies, the same for a seed (``sample_phenotypes``'s
    options)."""
    rng = np.random.default_rng(seed)
    p = sample_phenotypes(pmap, rng, n, teen_share, height_margin)
    return p, betas_for_phenotypes(pmap, p, rng, r2)
