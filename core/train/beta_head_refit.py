"""The `[BETA]` head's second phase: the T5 frozen, only the head trained, on body measurements.

Stage 2 trains the head jointly with the decoder on an L1 loss over the 10 betas. Not every beta
matters to how a body looks, and a shape text states heights and girths, so after the main steps
``head_steps`` more steps train the head alone on

    L1(betas) + ``head_measure_weight`` * (|height - true height| + |waist - true waist|)   (cm)

with height and waist of both bodies from ``shape_from_measurements.torch_measure`` (exact height
of the rest mesh, waist from the body's betas -> girth regression), so the loss reads the same
numbers the evaluation does. The decoder runs in eval mode without gradients (as at generation
time) and only for the two positions up to `[BETA]`, so a step costs a few milliseconds; examples
are drawn as in the main phase (captions, shape texts, none for a share of them), and a share
``head_synthetic_share`` describes NEW random bodies (``synthetic_bodies``, a pool of ``head_synthetic_bodies``): the dataset has a
few real skeletons and ~1,400 augmented bodies, and a head trained on those alone reads the numbers
of bodies it has seen far better than of new ones (``eval shape`` measures new ones).
"""
from __future__ import annotations

import torch

MEASURES = ("height_cm", "waist_cm")


def head_loss(head, states: torch.Tensor, betas: torch.Tensor, measure, weight: float) -> tuple:
    """(loss, L1 of the betas, mean |height error| + |waist error| in cm). ``measure``: (B,10) -> (B,2) cm."""
    pred = head(states)
    l1 = (pred - betas).abs().mean()
    with torch.no_grad():
        true = measure(betas)
    cm = (measure(pred) - true).abs().mean(0).sum()
    return l1 + weight * cm, l1.detach(), cm.detach()


def synthetic_bodies(body, girths, seed: int, n: int) -> tuple[list[str], torch.Tensor]:
    """A pool of ``n`` NEW bodies, the same for a seed: drawn from phenotypes (gender, age, muscle,
    weight, height: ``body.phenotype_sample``) when the body model has a phenotype map, else betas
    ~ N(0,1) clipped to +-2.5; measured (``fast_measure``: exact height and lengths, girths from
    ``girths``); each described either in the words people use (``phenotype_texts``: "a muscular
    young man", "a 72-year-old woman, slim", "a man, 6 ft 2, 200 lb") or by one of the dataset's
    measurement texts (the long sentence, a short numeric text or size words). (shape texts,
    (n, 10) betas). The head phase encodes the pool once and draws from it."""
    import random

    import numpy as np

    from ..body.measure import MEASUREMENTS
    from ..body.phenotype_sample import sample_bodies
    from ..body.shape_from_measurements import fast_measure
    from ..data.phenotype_captions import phenotype_texts
    from ..data.shape_text import adjective_shape_text, numeric_shape_text, shape_sentence

    rng = random.Random(seed)
    pmap = getattr(body, "phenotype_map", None)
    if pmap is not None:
        pheno, b = sample_bodies(pmap, seed, n, pmap.r2)
    else:
        pheno, b = None, np.clip(np.random.default_rng(seed).standard_normal((n, body.num_betas)), -2.5, 2.5)
    m = fast_measure(body, b, MEASUREMENTS, girths)
    shapes = []
    for i in range(n):
        mi = {k: float(m[i, j]) for j, k in enumerate(MEASUREMENTS)}
        key, kind = f"synthetic/{seed}/{i}", rng.randrange(6)
        if pheno is not None and kind >= 3:
            shapes.append(phenotype_texts(dict(zip(pmap.names, pheno[i])), mi, key, 1)[0])
        else:
            shapes.append(shape_sentence(mi) if kind == 0 else numeric_shape_text(mi, key) if kind == 1
                          else adjective_shape_text(mi, key))
    return shapes, torch.as_tensor(np.asarray(b), dtype=torch.float32)


class HeadExamples:
    """What the head phase reads: the main phase's examples (``T2MExamples``: captions, the clips'
    shape texts or none, their betas) and, for a share of each batch, a body of the new-body pool
    (``synthetic_bodies``) described beside a random training caption. ``measure``: the
    differentiable height/waist of OpenBody, whose betas -> girth regression ships."""

    def __init__(self, examples, vae_body: str | None, seed: int, pool_size: int):
        from ..body.load import load_body_model
        from ..body.shape_from_measurements import girth_regression, torch_measure
        from ..errors import ShapeMoveError

        body = load_body_model(None)
        if vae_body not in (None, body.name):
            raise ShapeMoveError(f"head_steps measure bodies of {body.name}; this SA-VAE was trained for "
                                 f"{vae_body!r} (set head_steps to 0)")
        self.examples, self.measure = examples, torch_measure(body, MEASURES)
        self.captions = sorted({t for caps in examples.captions.values() for t in caps})
        self.pool_texts, self.pool_betas = (synthetic_bodies(body, girth_regression(body), seed, pool_size)
                                            if pool_size else ([], torch.zeros(0, body.num_betas)))

    def batch(self, rng, n: int, share: float) -> tuple[list[str], list, torch.Tensor]:
        """(motion texts, shape texts (None: no shape text), (B, 10) betas) of about ``n`` examples."""
        n_new = int(round(n * share)) if self.pool_texts else 0
        drawn = (self.examples.sample(rng) for _ in range(n - n_new))
        batch = [e for e in drawn if e.get("motion_text") is not None]  # no motion-to-text examples
        pick = [rng.randrange(len(self.pool_texts)) for _ in range(n_new)]
        motions = [e["motion_text"] for e in batch] + [rng.choice(self.captions) for _ in pick]
        shapes = [e["shape_text"] for e in batch] + [self.pool_texts[i] for i in pick]
        betas = torch.cat([torch.stack([torch.as_tensor(e["betas"]) for e in batch]) if batch else
                           torch.zeros(0, self.pool_betas.shape[1]), self.pool_betas[pick]])
        return motions, shapes, betas
