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
``head_synthetic_share`` describes NEW random bodies (``synthetic_examples``): the dataset has a
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


def synthetic_examples(body, girths, captions: list[str], rng, n: int) -> tuple[list[str], list[str], torch.Tensor]:
    """``n`` examples of NEW bodies (the shape augmentation without a clip): betas ~ N(0,1) clipped
    to +-2.5, measured (``fast_measure``: exact height and lengths, girths from ``girths``), described
    by one of the dataset's shape texts (the long sentence, a short numeric text or size words, chosen
    at random), beside a random training caption. (motion texts, shape texts, (n, 10) betas);
    ``rng``: a ``random.Random`` (its state is the training run's, so a resumed run draws the same)."""
    import numpy as np

    from ..body.measure import MEASUREMENTS
    from ..body.shape_from_measurements import fast_measure
    from ..data.shape_text import adjective_shape_text, numeric_shape_text, shape_sentence

    np_rng = np.random.default_rng(rng.getrandbits(63))
    b = np.clip(np_rng.standard_normal((n, body.num_betas)), -2.5, 2.5)
    m = fast_measure(body, b, MEASUREMENTS, girths)
    shapes = []
    for i in range(n):
        mi = {k: float(m[i, j]) for j, k in enumerate(MEASUREMENTS)}
        key = f"{rng.getrandbits(32)}"
        kind = rng.randrange(3)
        shapes.append(shape_sentence(mi) if kind == 0 else numeric_shape_text(mi, key) if kind == 1
                      else adjective_shape_text(mi, key))
    return [rng.choice(captions) for _ in range(n)], shapes, torch.as_tensor(b, dtype=torch.float32)


class FreshShapes:
    """A text reader for the head phase: texts the run's ``StateCache`` holds (training captions and
    shape texts) come from it; others (the synthetic bodies' shape texts, each seen once) are encoded
    without being kept, so memory stays flat."""

    def __init__(self, cache):
        self.cache = cache

    def states(self, texts: list[str]):
        if all(str(t) in self.cache.states_of for t in texts):
            return self.cache.states(texts)
        return self.cache.encoder.states([str(t) for t in texts])
