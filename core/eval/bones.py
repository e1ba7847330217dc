"""Skeleton consistency metrics on joint positions (metres in, millimetres out).

* **bone-length variance** (Shape My Moves' "Bone Length Variance"): for each of the 21 bones of
  the 22-joint body (``BODY_BONES``), the standard deviation of its length over the frames;
  averaged over bones. A rigid skeleton gives 0.
* **bone-length error**: |length(t) - rest length of the target body| averaged over frames and
  bones; the rest lengths come from ``BodyModel.rest_joints(target_betas)``.
* **MPJPE**: mean Euclidean distance between corresponding joints, optionally after subtracting
  the root (pelvis) joint of each frame from both motions.
"""
from __future__ import annotations

import numpy as np
import torch

from ..body.skeleton import BODY_BONES, NUM_BODY_JOINTS
from ..errors import ShapeMoveError

_PARENT = np.array([p for p, _ in BODY_BONES])
_CHILD = np.array([c for _, c in BODY_BONES])


def _joints(x, name: str = "joints") -> np.ndarray:
    a = x.detach().cpu().numpy() if isinstance(x, torch.Tensor) else np.asarray(x)
    if a.ndim == 2:
        a = a[None]
    if a.ndim != 3 or a.shape[-1] != 3 or a.shape[1] < NUM_BODY_JOINTS:
        raise ShapeMoveError(f"{name} must be (T,>=22,3) joint positions in SMPL order, got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ShapeMoveError(f"{name} contains NaN or infinite values")
    return a.astype(np.float64)


def bone_lengths(joints) -> np.ndarray:
    """(T,>=22,3) joints -> (T,21) bone lengths in metres (``BODY_BONES`` order)."""
    j = _joints(joints)
    return np.linalg.norm(j[:, _CHILD] - j[:, _PARENT], axis=-1)


def target_bone_lengths(body, betas=None) -> np.ndarray:
    """(21,) rest bone lengths (m) of ``body`` with shape ``betas``."""
    with torch.no_grad():
        return bone_lengths(body.rest_joints(betas)[:1])[0]


def bone_length_variance_mm(joints) -> float:
    """Std over time of each bone length, averaged over the 21 bones, in mm."""
    return float(bone_lengths(joints).std(axis=0).mean() * 1000)


def bone_length_error_mm(joints, target_lengths) -> float:
    """Mean |bone length - target rest length| over frames and bones, in mm."""
    tgt = np.asarray(target_lengths, dtype=np.float64).reshape(-1)
    if tgt.shape != (len(BODY_BONES),):
        raise ShapeMoveError(f"target bone lengths must have {len(BODY_BONES)} values, got {tgt.shape[0]}")
    return float(np.abs(bone_lengths(joints) - tgt).mean() * 1000)


def mpjpe_mm(pred, target, root_aligned: bool = False) -> float:
    """Mean per-joint position error in mm between two (T,J,3) motions of equal shape."""
    p, t = _joints(pred, "pred"), _joints(target, "target")
    if p.shape != t.shape:
        raise ShapeMoveError(f"pred and target must have the same shape, got {p.shape} and {t.shape}")
    if root_aligned:
        p, t = p - p[:, :1], t - t[:, :1]
    return float(np.linalg.norm(p - t, axis=-1).mean() * 1000)
