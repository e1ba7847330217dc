"""Forward kinematics and linear blend skinning, batched in torch (the maths of ``smplx.lbs``).

Local rotations are relative to the parent joint's frame in the rest pose; with all identities
the body stands in its rest pose. Shapes: B batch, J joints, V vertices.
"""
from __future__ import annotations

import numpy as np
import torch


def axis_angle_to_matrix(aa: torch.Tensor) -> torch.Tensor:
    """(..., 3) axis-angle -> (..., 3, 3) rotation matrices (Rodrigues), safe at angle 0."""
    angle = torch.linalg.norm(aa, dim=-1, keepdim=True)
    small = angle < 1e-8
    axis = aa / torch.where(small, torch.ones_like(angle), angle)
    x, y, z = axis.unbind(-1)
    zero = torch.zeros_like(x)
    k = torch.stack([zero, -z, y, z, zero, -x, -y, x, zero], dim=-1).reshape(*aa.shape[:-1], 3, 3)
    s = torch.sin(angle)[..., None]
    c = torch.cos(angle)[..., None]
    eye = torch.eye(3, dtype=aa.dtype, device=aa.device).expand(k.shape)
    rot = eye + s * k + (1 - c) * (k @ k)
    # first-order term keeps gradients alive at zero angle
    rot_small = eye + torch.stack([zero, -aa[..., 2], aa[..., 1], aa[..., 2], zero, -aa[..., 0],
                                   -aa[..., 1], aa[..., 0], zero], dim=-1).reshape(k.shape)
    return torch.where(small[..., None], rot_small, rot)


def matrix_to_axis_angle(rot: torch.Tensor) -> torch.Tensor:
    """(..., 3, 3) rotation matrices -> (..., 3) axis-angle, robust near 0 and pi."""
    r = rot.double() if rot.dtype != torch.float64 else rot
    trace = r[..., 0, 0] + r[..., 1, 1] + r[..., 2, 2]
    cos = ((trace - 1) / 2).clamp(-1.0, 1.0)
    angle = torch.acos(cos)
    vec = torch.stack([r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0],
                       r[..., 1, 0] - r[..., 0, 1]], dim=-1)
    sin = torch.sin(angle)
    # generic case
    axis = vec / (2 * sin.clamp_min(1e-12))[..., None]
    out = axis * angle[..., None]
    # near zero: vec/2 is the first-order axis-angle
    out = torch.where((angle < 1e-6)[..., None], vec / 2, out)
    # near pi: axis from the symmetric part  (R + I)/2 = a a^T
    near_pi = angle > np.pi - 1e-3
    if near_pi.any():
        sym = (r + torch.eye(3, dtype=r.dtype, device=r.device)) / 2
        diag = torch.diagonal(sym, dim1=-2, dim2=-1).clamp_min(0)
        i = diag.argmax(-1, keepdim=True)
        col = torch.gather(sym, -1, i[..., None, :].expand(*sym.shape[:-1], 1)).squeeze(-1)
        a = col / torch.sqrt(torch.gather(diag, -1, i)).clamp_min(1e-12)
        # sign so that it agrees with the (small) antisymmetric part
        sign = torch.where((a * vec).sum(-1, keepdim=True) < 0, -1.0, 1.0).to(r.dtype)
        a = a / torch.linalg.norm(a, dim=-1, keepdim=True).clamp_min(1e-12) * sign
        out = torch.where(near_pi[..., None], a * angle[..., None], out)
    return out.to(rot.dtype)


def as_rotation_matrices(rotations: torch.Tensor) -> torch.Tensor:
    """Accept (B,J,3) axis-angle or (B,J,3,3) matrices; return (B,J,3,3) matrices."""
    if rotations.dim() == 4 and rotations.shape[-2:] == (3, 3):
        return rotations
    if rotations.dim() == 3 and rotations.shape[-1] == 3:
        return axis_angle_to_matrix(rotations)
    raise ValueError(f"rotations must be (B,J,3) axis-angle or (B,J,3,3) matrices, got {tuple(rotations.shape)}")


def forward_kinematics(rotmats: torch.Tensor, rest_joints: torch.Tensor, parents) -> tuple[torch.Tensor, torch.Tensor]:
    """Pose a skeleton.

    rotmats (B,J,3,3) local rotations, rest_joints (B,J,3) rest-pose joint positions,
    parents (J,) with parents[0] = -1 and parents[j] < j.
    Returns posed joints (B,J,3) (root at its rest position) and world transforms (B,J,4,4).
    """
    parents = [int(p) for p in parents]
    B, J = rest_joints.shape[:2]
    rel = rest_joints.clone()
    rel[:, 1:] = rest_joints[:, 1:] - rest_joints[:, parents[1:]]
    local = torch.zeros(B, J, 4, 4, dtype=rotmats.dtype, device=rotmats.device)
    local[..., :3, :3] = rotmats
    local[..., :3, 3] = rel
    local[..., 3, 3] = 1
    chain = [local[:, 0]]
    for j in range(1, J):
        chain.append(chain[parents[j]] @ local[:, j])
    world = torch.stack(chain, dim=1)
    return world[..., :3, 3], world


def skinning_transforms(world: torch.Tensor, rest_joints: torch.Tensor) -> torch.Tensor:
    """World transforms (B,J,4,4) -> transforms that move rest-pose vertices (remove rest joint)."""
    offset = (world[..., :3, :3] @ rest_joints[..., None]).squeeze(-1)
    out = world.clone()
    out[..., :3, 3] = world[..., :3, 3] - offset
    return out


def linear_blend_skinning(vertices: torch.Tensor, weights: torch.Tensor, transforms: torch.Tensor) -> torch.Tensor:
    """vertices (B,V,3) rest pose, weights (V,J), transforms (B,J,4,4) from ``skinning_transforms``."""
    T = torch.einsum("vj,bjmn->bvmn", weights, transforms)
    return (T[..., :3, :3] @ vertices[..., None]).squeeze(-1) + T[..., :3, 3]
