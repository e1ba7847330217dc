"""SA-VAE training losses. Features are (B, T, 263) HumanML3D vectors; joints (B, T, 22, 3) in
metres, Y up, ground at y = 0 (the dataset grounds every clip on its body's mesh soles).

Joints come from ``core.motion.features.joints_from_features`` (HumanML3D recover_from_ric); foot
contacts (B, T, 4) in the contact channels' order ``CONTACT_JOINTS`` (left ankle, left foot, right
ankle, right foot): the dataset's stored contacts, or the target's contact channels.

Ground losses act on the SOLES when ``sole_offsets`` (B, 4) are given (``body.soles.sole_offsets``
of the body with those betas, joints 7, 8, 10, 11): a foot joint's sole height is its height minus
its rest height above the sole, so a planted heel/toe is on the floor at sole height 0.
"""
from __future__ import annotations

import torch
import torch.nn.functional as F

from ..body.skeleton import BODY_BONES, FOOT_JOINTS, FOOT_LEFT, FOOT_RIGHT
from ..constants import FPS
from ..motion.features import feature_slices, joints_from_features

CONTACT_SLICE = feature_slices["contacts"]
CONTACT_JOINTS = FOOT_LEFT + FOOT_RIGHT   # joints of the 4 contact channels: 7, 10, 8, 11
SOLE_TO_CONTACT = [0, 2, 1, 3]            # sole_offsets of FOOT_JOINTS (7, 8, 10, 11) -> CONTACT_JOINTS order
GRAVITY = 9.81
# rough segment masses (fractions, de Leva 1996) lumped on the 22 joints, for the CoM of the ZMP term
_MASS = torch.tensor([0.11, 0.10, 0.10, 0.09, 0.045, 0.045, 0.09, 0.012, 0.012, 0.09, 0.002, 0.002,
                      0.03, 0.01, 0.01, 0.07, 0.027, 0.027, 0.016, 0.016, 0.006, 0.006])
BOS_MARGIN = 0.04                          # m: half a foot's width around the contact joints
_PARENT = [p for p, _ in BODY_BONES]
_CHILD = [c for _, c in BODY_BONES]


def bone_lengths(joints: torch.Tensor) -> torch.Tensor:
    """(..., 22, 3) -> (..., 21) lengths of ``BODY_BONES`` (m)."""
    return (joints[..., _CHILD, :] - joints[..., _PARENT, :]).norm(dim=-1)


def masked_mean(x: torch.Tensor, valid: torch.Tensor | None) -> torch.Tensor:
    """Mean of ``x`` (B, T, ...) over the frames where ``valid`` (B, T) is 1 (None: all of them)."""
    if valid is None:
        return x.mean()
    w = valid.to(x).reshape(valid.shape + (1,) * (x.dim() - 2)).expand_as(x)
    return (x * w).sum() / w.sum().clamp(min=1)


def pairs(valid: torch.Tensor | None) -> torch.Tensor | None:
    """(B, T) frames -> (B, T-1) steps from one valid frame to a valid next one."""
    return None if valid is None else valid[:, 1:] * valid[:, :-1]


def velocity_loss(pred: torch.Tensor, target: torch.Tensor, valid: torch.Tensor | None = None) -> torch.Tensor:
    """Smooth L1 between the frame-to-frame differences of (B, T, D) sequences (steps between
    ``valid`` frames)."""
    return masked_mean(F.smooth_l1_loss(pred[:, 1:] - pred[:, :-1], target[:, 1:] - target[:, :-1], reduction="none"),
                       pairs(valid))


def sole_heights(joints: torch.Tensor, sole_offsets: torch.Tensor | None) -> torch.Tensor:
    """(B,T,22,3) joints -> (B,T,4) heights (m) of the contact joints' soles (``CONTACT_JOINTS``
    order); ``sole_offsets`` (B,4) of joints 7, 8, 10, 11, or None for the joints' own heights."""
    h = joints[..., CONTACT_JOINTS, 1]
    if sole_offsets is None:
        return h
    return h - sole_offsets[:, SOLE_TO_CONTACT][:, None, :].to(h)


def penetration_loss(joints: torch.Tensor, sole_offsets: torch.Tensor | None = None,
                     valid: torch.Tensor | None = None) -> torch.Tensor:
    """Mean depth (m) below the ground y = 0 over all joints and frames; with ``sole_offsets`` the
    ankles and feet count with their soles (their joints may not go below their sole offset)."""
    depth = F.relu(-joints[..., 1])
    if sole_offsets is not None:
        depth = depth.clone()
        depth[..., CONTACT_JOINTS] = F.relu(-sole_heights(joints, sole_offsets))
    return masked_mean(depth, valid)


def floating_loss(joints: torch.Tensor, target_joints: torch.Tensor, contacts: torch.Tensor,
                  sole_offsets: torch.Tensor | None = None) -> torch.Tensor:
    """(B,T,22,3), (B,T,22,3), (B,T,4) contacts. With ``sole_offsets``: mean height (m) of the sole
    of each contact joint above the floor, over the contact events (a planted heel/toe stands on
    y = 0). Without: on frames where the target has a foot in contact, how far the lowest foot joint
    is above the target's lowest foot joint (or the ground, if the target's is below it)."""
    if sole_offsets is not None:
        mask = (contacts > 0.5).float()
        return (F.relu(sole_heights(joints, sole_offsets)) * mask).sum() / mask.sum().clamp(min=1)
    low = joints[..., FOOT_JOINTS, 1].amin(-1)
    ref = target_joints[..., FOOT_JOINTS, 1].amin(-1).clamp(min=0)
    mask = (contacts > 0.5).any(-1).float()
    return (F.relu(low - ref) * mask).sum() / mask.sum().clamp(min=1)


def foot_slide_loss(joints: torch.Tensor, contacts: torch.Tensor, valid: torch.Tensor | None = None) -> torch.Tensor:
    """Horizontal (XZ) displacement (m/frame) of the ankle/foot joints from frame t to t+1 while the
    target says that joint is in contact at t; averaged over the contact events. (The sole of a
    planted joint moves as the joint does: no offset needed.)"""
    feet = joints[..., CONTACT_JOINTS, :]                         # (B,T,4,3)
    step = (feet[:, 1:, :, [0, 2]] - feet[:, :-1, :, [0, 2]]).norm(dim=-1)
    mask = (contacts[:, :-1] > 0.5).float()
    if valid is not None:   # no step into a padded frame
        mask = mask * pairs(valid)[..., None].to(mask)
    return (step * mask).sum() / mask.sum().clamp(min=1)


def zero_moment_points(joints: torch.Tensor, fps: float = FPS) -> torch.Tensor:
    """(B,T,22,3) joints -> (B,T,2) XZ of the zero-moment point of the cart-table model (HUMOS):
    CoM = mass-weighted joints, acceleration by central differences (ends copy their neighbour),
    x_zmp = c_x - c_y a_x / (a_y + g). Frames in free fall (a_y + g <= 0.1 g) are clamped."""
    m = _MASS.to(joints)
    com = (joints * m[:, None]).sum(-2) / m.sum()                   # (B,T,3)
    acc = torch.zeros_like(com)
    if com.shape[1] >= 3:
        acc[:, 1:-1] = (com[:, 2:] - 2 * com[:, 1:-1] + com[:, :-2]) * fps * fps
        acc[:, 0], acc[:, -1] = acc[:, 1], acc[:, -2]
    denom = (acc[..., 1] + GRAVITY).clamp(min=0.1 * GRAVITY)
    return torch.stack([com[..., 0] - com[..., 1] * acc[..., 0] / denom,
                        com[..., 2] - com[..., 1] * acc[..., 2] / denom], -1)


def _segment_distance(p: torch.Tensor, a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    ab = b - a
    t = ((p - a) * ab).sum(-1) / (ab * ab).sum(-1).clamp(min=1e-9)
    return (p - a - t.clamp(0, 1)[..., None] * ab).norm(dim=-1)


def dynamic_stability_loss(joints: torch.Tensor, contacts: torch.Tensor, margin: float = BOS_MARGIN) -> torch.Tensor:
    """HUMOS's dynamic-stability term on joints: how far (m) the zero-moment point lies outside the
    base of support, averaged over the frames with a contact. The base of support is approximated by
    the segments between every pair of contact joints (and the joints themselves), widened by
    ``margin`` (half a foot). (B,T,22,3), (B,T,4) contacts in ``CONTACT_JOINTS`` order."""
    zmp = zero_moment_points(joints)[:, :, None, None, :]              # (B,T,1,1,2)
    feet = joints[..., CONTACT_JOINTS, :][..., [0, 2]]                  # (B,T,4,2)
    on = contacts > 0.5
    d = _segment_distance(zmp, feet[:, :, :, None], feet[:, :, None, :])  # (B,T,4,4)
    pair = on[..., :, None] & on[..., None, :]
    d = torch.where(pair, d, torch.full_like(d, float("inf"))).flatten(-2).amin(-1)
    frame = on.any(-1)
    out = F.relu(torch.where(frame, d, torch.zeros_like(d)) - margin)
    return (out * frame).sum() / frame.sum().clamp(min=1)


def root_travel_loss(joints: torch.Tensor, target_joints: torch.Tensor, pred: torch.Tensor,
                     target: torch.Tensor, valid: torch.Tensor | None = None) -> torch.Tensor:
    """How well the root's travel is carried: the mean horizontal distance (m) between the predicted
    and the target root trajectories over the window (both start at the origin, so a shrunk speed
    accumulates), plus smooth L1 on the normalized root channels (rotation velocity, XZ velocity,
    height). The root channels are 4 of 263 features: under the plain reconstruction term their
    errors are diluted ~65x and the decoder learns to under-shoot speed (HumanML3D's code up-weights
    them for the same reason)."""
    track = masked_mean((joints[..., 0, :][..., [0, 2]] - target_joints[..., 0, :][..., [0, 2]]).norm(dim=-1), valid)
    return track + masked_mean(F.smooth_l1_loss(pred[..., :4], target[..., :4], reduction="none"), valid)


def bone_length_loss(joints: torch.Tensor, target_bones: torch.Tensor, valid: torch.Tensor | None = None) -> torch.Tensor:
    """Mean |bone length - target rest length| (m). joints (B,T,22,3), target_bones (B,21)."""
    return masked_mean((bone_lengths(joints) - target_bones[:, None, :]).abs(), valid)


def vae_losses(pred: torch.Tensor, target: torch.Tensor, mean: torch.Tensor, std: torch.Tensor, weights,
               target_bones: torch.Tensor | None = None, sole_offsets: torch.Tensor | None = None,
               contacts: torch.Tensor | None = None, valid: torch.Tensor | None = None) -> dict:
    """All SA-VAE losses for normalized prediction/target features (B, T, 263).

    ``weights`` is a ``LossWeights``; ``target_bones`` (B, 21) are the rest bone lengths of the
    target body (from ``BodyModel.rest_joints(betas)``); when None they are the median bone
    lengths of the target motion. ``sole_offsets`` (B, 4): the target body's sole offsets of joints
    7, 8, 10, 11 (``body.soles.sole_offsets``): the ground losses then act on the soles.
    ``contacts`` (B, T, 4) in ``CONTACT_JOINTS`` order (the dataset's stored contacts); None = the
    target's contact channels. ``valid`` (B, T): 1 on a clip's frames, 0 on a short clip's padding
    (``MotionClips``), which no term counts; None: every frame. Returns a dict of scalar tensors
    with the weighted sum in 'total'.
    """
    out = {"recon": masked_mean(F.smooth_l1_loss(pred, target, reduction="none"), valid),
           "vel": velocity_loss(pred, target, valid)}
    if getattr(weights, "recon_mse", 0.0):
        out["recon_mse"] = masked_mean(F.mse_loss(pred, target, reduction="none"), valid)
    stability = getattr(weights, "dyn_stability", 0.0)
    physical = stability or any(getattr(weights, k, 0.0) for k in ("bone", "floating", "slide", "penetrate", "root"))
    if physical:
        pred_f, target_f = pred * std + mean, target * std + mean
        joints = joints_from_features(pred_f)
        with torch.no_grad():
            target_joints = joints_from_features(target_f)
            if target_bones is None:
                target_bones = bone_lengths(target_joints).median(dim=1).values
        if contacts is None:
            contacts = target_f[..., CONTACT_SLICE]
        contacts = contacts.to(joints)
        if valid is not None:   # no contact on padding: the ground terms count the clip's frames alone
            contacts = contacts * valid.to(joints)[..., None]
        out["bone"] = bone_length_loss(joints, target_bones, valid)
        out["floating"] = floating_loss(joints, target_joints, contacts, sole_offsets)
        out["slide"] = foot_slide_loss(joints, contacts, valid)
        out["penetrate"] = penetration_loss(joints, sole_offsets, valid)
        if getattr(weights, "root", 0.0):
            out["root"] = root_travel_loss(joints, target_joints, pred, target, valid)
        if stability:
            out["dyn_stability"] = dynamic_stability_loss(joints, contacts)
    out["total"] = sum(getattr(weights, k) * v for k, v in out.items())
    return out
