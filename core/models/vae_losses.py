"""SA-VAE training losses. Features are (B, T, 263) HumanML3D vectors; joints (B, T, 22, 3) in
metres, Y up, ground at y = 0 (the dataset puts the lowest foot joint of a clip on it).

Joints come from ``core.motion.features.joints_from_features`` (HumanML3D recover_from_ric); foot
contacts from the target's contact channels (left ankle, left foot, right ankle, right foot).
"""
from __future__ import annotations

import torch
import torch.nn.functional as F

from ..body.skeleton import BODY_BONES, FOOT_JOINTS, FOOT_LEFT, FOOT_RIGHT
from ..motion.features import feature_slices, joints_from_features

CONTACT_SLICE = feature_slices["contacts"]
CONTACT_JOINTS = FOOT_LEFT + FOOT_RIGHT   # joints of the 4 contact channels: 7, 10, 8, 11
_PARENT = [p for p, _ in BODY_BONES]
_CHILD = [c for _, c in BODY_BONES]


def bone_lengths(joints: torch.Tensor) -> torch.Tensor:
    """(..., 22, 3) -> (..., 21) lengths of ``BODY_BONES`` (m)."""
    return (joints[..., _CHILD, :] - joints[..., _PARENT, :]).norm(dim=-1)


def velocity_loss(pred: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Smooth L1 between the frame-to-frame differences of (B, T, D) sequences."""
    return F.smooth_l1_loss(pred[:, 1:] - pred[:, :-1], target[:, 1:] - target[:, :-1])


def penetration_loss(joints: torch.Tensor) -> torch.Tensor:
    """Mean depth (m) of joints below the ground y = 0, over all joints and frames."""
    return F.relu(-joints[..., 1]).mean()


def floating_loss(joints: torch.Tensor, target_joints: torch.Tensor, contacts: torch.Tensor) -> torch.Tensor:
    """On frames where the target has a foot in contact: how far (m) the lowest foot joint is above
    the target's lowest foot joint (or the ground, if the target's is below it). (B,T,22,3), (B,T,4)."""
    low = joints[..., FOOT_JOINTS, 1].amin(-1)
    ref = target_joints[..., FOOT_JOINTS, 1].amin(-1).clamp(min=0)
    mask = (contacts > 0.5).any(-1).float()
    return (F.relu(low - ref) * mask).sum() / mask.sum().clamp(min=1)


def foot_slide_loss(joints: torch.Tensor, contacts: torch.Tensor) -> torch.Tensor:
    """Horizontal (XZ) displacement (m/frame) of the ankle/foot joints from frame t to t+1 while the
    target says that joint is in contact at t; averaged over the contact events."""
    feet = joints[..., CONTACT_JOINTS, :]                         # (B,T,4,3)
    step = (feet[:, 1:, :, [0, 2]] - feet[:, :-1, :, [0, 2]]).norm(dim=-1)
    mask = (contacts[:, :-1] > 0.5).float()
    return (step * mask).sum() / mask.sum().clamp(min=1)


def bone_length_loss(joints: torch.Tensor, target_bones: torch.Tensor) -> torch.Tensor:
    """Mean |bone length - target rest length| (m). joints (B,T,22,3), target_bones (B,21)."""
    return (bone_lengths(joints) - target_bones[:, None, :]).abs().mean()


def vae_losses(pred: torch.Tensor, target: torch.Tensor, mean: torch.Tensor, std: torch.Tensor, weights,
               target_bones: torch.Tensor | None = None) -> dict:
    """All SA-VAE losses for normalized prediction/target features (B, T, 263).

    ``weights`` is a ``LossWeights``; ``target_bones`` (B, 21) are the rest bone lengths of the
    target body (from ``BodyModel.rest_joints(betas)``); when None they are the median bone
    lengths of the target motion. Returns a dict of scalar tensors with the weighted sum in 'total'.
    """
    out = {"recon": F.smooth_l1_loss(pred, target), "vel": velocity_loss(pred, target)}
    physical = any(getattr(weights, k) for k in ("bone", "floating", "slide", "penetrate"))
    if physical:
        pred_f, target_f = pred * std + mean, target * std + mean
        joints = joints_from_features(pred_f)
        with torch.no_grad():
            target_joints = joints_from_features(target_f)
            if target_bones is None:
                target_bones = bone_lengths(target_joints).median(dim=1).values
        contacts = target_f[..., CONTACT_SLICE]
        out["bone"] = bone_length_loss(joints, target_bones)
        out["floating"] = floating_loss(joints, target_joints, contacts)
        out["slide"] = foot_slide_loss(joints, contacts)
        out["penetrate"] = penetration_loss(joints)
    out["total"] = sum(getattr(weights, k) * v for k, v in out.items())
    return out
