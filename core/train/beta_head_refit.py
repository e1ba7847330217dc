"""The `[BETA]` head's second phase: the T5 frozen, only the head trained, on body measurements.

Stage 2 trains the head jointly with the decoder on an L1 loss over the 10 betas. Not every beta
matters to how a body looks, and a shape text states heights and girths, so after the main steps
``head_steps`` more steps train the head alone on

    L1(betas) + ``head_measure_weight`` * (|height - true height| + |waist - true waist|)   (cm)

with height and waist of both bodies from ``shape_from_measurements.torch_measure`` (exact height
of the rest mesh, waist from the body's betas -> girth regression), so the loss reads the same
numbers the evaluation does. The decoder runs in eval mode without gradients (as at generation
time) and only for the two positions up to `[BETA]`, so a step costs a few milliseconds; examples
are drawn as in the main phase (captions, shape texts, none for a share of them).
"""
from __future__ import annotations

import torch

MEASURES = ("height_cm", "waist_cm")


def beta_states(model, inputs) -> torch.Tensor:
    """(B, d_model) decoder states whose input is `[BETA]`, for ``model.inputs_for`` inputs."""
    v = model.vocab
    with torch.no_grad():
        enc, mask = model.encode(*inputs)
        seq = torch.tensor([[v.pad_id, v.beta_id]] * enc.shape[0], device=enc.device)
        _, hidden, _ = model.step(enc, mask, seq)
    return hidden[:, 1]


def head_loss(head, states: torch.Tensor, betas: torch.Tensor, measure, weight: float) -> tuple:
    """(loss, L1 of the betas, mean |height error| + |waist error| in cm). ``measure``: (B,10) -> (B,2) cm."""
    pred = head(states)
    l1 = (pred - betas).abs().mean()
    with torch.no_grad():
        true = measure(betas)
    cm = (measure(pred) - true).abs().mean(0).sum()
    return l1 + weight * cm, l1.detach(), cm.detach()
