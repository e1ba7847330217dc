"""Encoding by search: the codes whose decoding comes closest to the motion (analysis by synthesis).

The SA-VAE's encoders map a motion to codes in one pass, but nothing makes those the codes the
decoder turns back into that motion best: the encoders see the normalized motion (canonical body)
and were trained only together with a decoder. When the motion itself is known (a captured take
being retargeted, a clip whose reconstruction is measured), the codes can be searched for:

    tokens = search_tokens(vae, encode_latents(vae, x), betas, shaped_features)   # packed (motion_codes.pack)

starts from the encoders' latents (base and residual), decodes them with the motion's own body
(``betas``) through the straight-through FSQ rounding (rounded in the forward pass, as training
does), compares the decoded joints with the motion's own on that body (read from its shape-aware
features, as the decoded ones are) and moves the latents with Adam (cosine-decayed steps). The
loss (``joint_loss``) is what the codec is judged by: the root-aligned joint distance, the
distance with the root's path, the bone lengths' error and the root's travel per second. After
every step the rounded codes are scored and the best kept, so the result is never further from
the motion, by that loss, than the encoders' own codes. Deterministic for a motion, a codec and
a thread count. The weights were chosen on validation clips (docs/codec.md).

A codec without a residual code searches its base codes. Long takes are searched ``window`` tokens
at a time (the codes around a window held fixed as its context), so memory stays bounded.
The T5 never reads these codes (it writes and reads the encoders' base codes); the search serves
motions that are encoded to be decoded again: retargeting (``generation/retarget.py``) and the
codec's own measurements (``eval recon``, ``eval speed``).
"""
from __future__ import annotations

import math

import numpy as np
import torch

from ..constants import FPS
from ..errors import ShapeMoveError
from ..motion.features import joints_from_features
from .vae_losses import bone_lengths

STEPS = 200
LR = 0.05
TRAJECTORY_WEIGHT = 0.1
BONE_WEIGHT = 6.0
VELOCITY_WEIGHT = 0.2
WINDOW = 256  # tokens searched at once (about 1,024 frames)
TICK = 10  # steps between progress reports



def joint_loss(joints: torch.Tensor, target: torch.Tensor, trajectory_weight: float = TRAJECTORY_WEIGHT,
               bone_weight: float = BONE_WEIGHT, velocity_weight: float = VELOCITY_WEIGHT):
    """The measures the codec is judged by, as one loss (m): the mean joint distance with each
    frame's root aligned (root-aligned MPJPE), plus ``trajectory_weight`` x the mean distance with
    the root's path (MPJPE), plus ``bone_weight`` x the mean absolute error of the 21 bone lengths,
    plus ``velocity_weight`` x the mean error of the root's horizontal travel over each second (its
    mean velocity, m/s: what makes a decoded walk as fast as the take):
    joints and target (T, 22, 3), Y up, at ``FPS``."""
    aligned = (joints - joints[:, :1]) - (target - target[:, :1])
    loss = _norm(aligned).mean() + trajectory_weight * _norm(joints - target).mean()
    if bone_weight:
        loss = loss + bone_weight * (bone_lengths(joints) - bone_lengths(target)).abs().mean()
    if velocity_weight and len(joints) > 1:
        k = min(FPS, len(joints) - 1)  # the root's horizontal travel over each second (m/s)
        travel = lambda j: (j[k:, 0] - j[:-k, 0])[:, [0, 2]] * (FPS / k)  # noqa: E731
        loss = loss + velocity_weight * _norm(travel(joints) - travel(target)).mean()
    return loss


def _norm(v):
    return ((v ** 2).sum(-1) + 1e-12).sqrt()  # (the eps keeps the gradient finite at 0)


def _decoded_joints(vae, base, residual, betas):
    feats = vae.decode_chunked(base, betas, residual=residual)
    return joints_from_features(vae.denormalize(feats)[0])


def _search_window(vae, zb, zr, fixed_b, fixed_r, lo, hi, betas, target, steps, lr, weights, tick=None):
    """Adam on the latents of tokens [lo, hi) of the span decoded (the rest of the span fixed),
    scored on the span's first len(target) frames; returns the best rounded (base, residual) codes
    of the window. ``tick(fraction of the steps)`` every ``TICK`` steps."""
    q, rq = vae.quantizer, getattr(vae, "residual_quantizer", None)
    zb = zb[:, lo:hi].clone().requires_grad_(True)
    params = [zb]
    if rq is not None:
        zr = zr[:, lo:hi].clone().requires_grad_(True)
        params.append(zr)
    opt = torch.optim.Adam(params, lr=lr)
    cosine = lambda i: 0.5 * (1 + math.cos(math.pi * min(i, steps) / max(steps, 1)))  # noqa: E731
    sched = torch.optim.lr_scheduler.LambdaLR(opt, cosine)
    best, best_codes = float("inf"), None
    for i in range(steps + 1):
        if tick is not None and i % TICK == 0:
            tick(i / max(steps, 1))
        cb = torch.cat([fixed_b[:, :lo], q.quantize(zb), fixed_b[:, hi:]], 1)
        cr = None if rq is None else torch.cat([fixed_r[:, :lo], rq.quantize(zr), fixed_r[:, hi:]], 1)
        loss = joint_loss(_decoded_joints(vae, cb, cr, betas)[:len(target)], target, *weights)
        value = float(loss.detach())
        if value < best:
            best = value
            best_codes = (cb[:, lo:hi].detach().clone(), None if cr is None else cr[:, lo:hi].detach().clone())
        opt.zero_grad()
        loss.backward()
        opt.step()
        sched.step()
    return best_codes


def search_tokens(vae, latents, betas, target_features, steps: int = STEPS, lr: float = LR,
                  trajectory_weight: float = TRAJECTORY_WEIGHT, bone_weight: float = BONE_WEIGHT,
                  velocity_weight: float = VELOCITY_WEIGHT, window: int = WINDOW, progress=None) -> torch.Tensor:
    """The encoders' latents of a motion (base (1, N, C), residual (1, N, R) or None:
    ``generation.retarget.encode_latents``), its own betas (10,) and its shape-aware features
    (4N, 263; not normalized: the joints it is compared with are read from them per window, as the
    decoded ones are, ``joints_from_features``) -> tokens (N,), packed with the residual when the
    codec has one. ``progress(fraction)`` every ``TICK`` steps and after each window (it may raise
    to stop the search, as a cancelled job does)."""
    zb, zr = latents
    down = vae.cfg.downsample
    n = zb.shape[1] if zb.dim() == 3 else 0
    if n == 0 or zb.shape[0] != 1:
        raise ShapeMoveError(f"search_tokens: base latents must be (1, N >= 1, C), got {tuple(zb.shape)}")
    if vae.has_residual != (zr is not None) or (zr is not None and zr.shape[:2] != zb.shape[:2]):
        raise ShapeMoveError("search_tokens: the residual latents must match the codec and the base latents")
    target_features = torch.as_tensor(np.asarray(target_features), dtype=torch.float64)
    if tuple(target_features.shape) != (n * down, vae.cfg.feature_dim):
        raise ShapeMoveError(f"search_tokens: target features must be {(n * down, vae.cfg.feature_dim)}, "
                             f"got {tuple(target_features.shape)}")
    if steps < 0 or window < 1:
        raise ShapeMoveError("search_tokens: steps must be >= 0 and window >= 1")
    betas = torch.as_tensor(betas, dtype=torch.float32).reshape(1, -1)
    residual = zr is not None
    was_training = vae.training
    vae.eval()
    grads = [p.requires_grad for p in vae.parameters()]
    for p in vae.parameters():
        p.requires_grad_(False)
    try:
        with torch.no_grad():
            cb = vae.quantizer.quantize(zb)
            cr = vae.residual_quantizer.quantize(zr) if residual else None
        # a window's span, decoded, is cut into the chunks the whole take is cut into when it is
        # decoded (decode_long: chunks start every `step` tokens): it starts one step before the
        # window (codes already searched) and ends a chunk after it (the encoders' codes). It is
        # scored up to the window's end, the context before it included (its frames hear the
        # window's codes), not after it (searched next).
        chunk, overlap = vae.chunking()
        step = chunk - overlap
        window = max(step, window // step * step)
        starts = list(range(0, n, window))
        for i, s in enumerate(starts):
            e = min(n, s + window)
            lo, hi = max(0, s - step), min(n, e + chunk)
            target = joints_from_features(target_features[lo * down:e * down]).float()
            with torch.enable_grad():
                b, r = _search_window(vae, zb[:, lo:hi], None if zr is None else zr[:, lo:hi],
                                      cb[:, lo:hi], None if cr is None else cr[:, lo:hi], s - lo, e - lo,
                                      betas, target, steps, lr, (trajectory_weight, bone_weight, velocity_weight),
                                      None if progress is None else lambda f, i=i: progress((i + f) / len(starts)))
            cb[:, s:e] = b
            if residual:
                cr[:, s:e] = r
            if progress is not None:
                progress((i + 1) / len(starts))
    finally:
        for p, g in zip(vae.parameters(), grads):
            p.requires_grad_(g)
        vae.train(was_training)
    return vae.tokens_of_codes(cb, cr)[0]
