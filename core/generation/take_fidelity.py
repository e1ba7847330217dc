"""Does the codec carry this take? The error of a take's codes decoded on the take's own body.

Retargeting through the SA-VAE (``retarget.py``) re-performs a captured take from its codes; where
the codes cannot carry what the body does (a fast kick, a slash: the codec's ceiling,
``tools/codec_action_check.py``), the re-performed take is a different, flatter motion. This is
measured where it is known, before anything is moved to a new body: the codes decoded with the
take's own betas, their joints (read from the decoded shape-aware features, as ``code_search``
compares them) against the take's own (read from its shape-aware features the same way):

    err = take_error_mm(codes, vae, betas, shaped_feats)   # (T,) mm, root-aligned, per frame
    worst_second_mm(err)                                  # the worst second's mean
    worst_take_error_mm(codes, vae, betas, shaped_feats)  # both, what the fallbacks compare with LOST_TAKE_MM

An action lasts about a second, so a short kick in a long walk is judged by its own second, not
diluted by the walk. ``LOST_TAKE_MM`` is where the decoded action stops being the captured one
(chosen on captured training clips of every action and checked on test clips: docs/design-notes.md,
Planting and retargeting).
"""
from __future__ import annotations

import numpy as np
import torch

from ..constants import FPS
from ..errors import ShapeMoveError
from ..motion.features import joints_from_features
from .decode import decode_features

LOST_TAKE_MM = 100.0  # worst second's root-aligned joint error (mm) above which the codes lose the take
SECOND = FPS          # frames in the window an action is judged over


def take_error_mm(codes, vae, betas, shaped_feats) -> np.ndarray:
    """(T,) per-frame root-aligned mean joint distance (mm) between ``codes`` decoded on the body
    ``betas`` (the take's own) and the take's shape-aware features ``shaped_feats`` (>= T, 263)
    on that body; T = 4 x len(codes) frames."""
    feats = decode_features([int(c) for c in codes], vae, betas).double()
    shaped = np.asarray(shaped_feats)
    if shaped.ndim != 2 or shaped.shape[1] != feats.shape[1] or len(shaped) < len(feats):
        raise ShapeMoveError(f"take_error_mm: the take's features must be (>= {len(feats)}, {feats.shape[1]}), "
                             f"got {shaped.shape}")
    with torch.no_grad():
        dec = joints_from_features(feats).numpy()
        tgt = joints_from_features(torch.as_tensor(shaped[:len(feats)], dtype=torch.float64)).numpy()
    aligned = (dec - dec[:, :1]) - (tgt - tgt[:, :1])
    return np.linalg.norm(aligned, axis=-1).mean(1) * 1000.0


@torch.no_grad()
def worst_take_error_mm(codes, vae, betas, shaped_feats) -> float:
    """``worst_second_mm`` of ``take_error_mm``: how far the codes miss the take in its worst second."""
    return worst_second_mm(take_error_mm(codes, vae, betas, shaped_feats))


def worst_second_mm(err: np.ndarray, frames: int = SECOND) -> float:
    """The largest mean of ``err`` over ``frames`` consecutive frames (the whole take's mean when
    it is shorter)."""
    err = np.asarray(err, np.float64)
    if err.ndim != 1 or len(err) == 0:
        raise ShapeMoveError(f"worst_second_mm: a (T >= 1,) error, got shape {err.shape}")
    if len(err) <= frames:
        return float(err.mean())
    c = np.concatenate([[0.0], np.cumsum(err)])
    return float(((c[frames:] - c[:-frames]) / frames).max())
