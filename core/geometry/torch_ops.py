"""Torch twins of ``rotations`` and ``fk`` for the code that needs gradients (IK, the body
model, betas fitting). Same names, shapes and conventions as the numpy functions."""
from __future__ import annotations

import torch


def axis_angle_to_matrix(aa: torch.Tensor) -> torch.Tensor:
    """(..., 3) axis-angle -> (..., 3, 3) rotation matrices (Rodrigues); gradients stay finite
    at angle 0 (first-order term)."""
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
    rot_small = eye + torch.stack([zero, -aa[..., 2], aa[..., 1], aa[..., 2], zero, -aa[..., 0],
                                   -aa[..., 1], aa[..., 0], zero], dim=-1).reshape(k.shape)
    return torch.where(small[..., None], rot_small, rot)


def forward_kinematics(rotations: torch.Tensor, rest_joints: torch.Tensor, parents) -> tuple[torch.Tensor, torch.Tensor]:
    """Pose a skeleton (differentiable).

    rotations (..., J, 3, 3) local rotations, rest_joints (..., J, 3) rest-pose joint positions,
    parents (J,) with -1 for roots and parents[j] < j. Returns posed joints (..., J, 3), each root
    at its rest position, and world rotations (..., J, 3, 3).
    """
    parents = [int(p) for p in parents]
    shape = torch.broadcast_shapes(rotations.shape[:-2], rest_joints.shape[:-1])
    rot = rotations.expand(*shape, 3, 3)
    rest = rest_joints.expand(*shape, 3)
    world: list[torch.Tensor] = []
    pos: list[torch.Tensor] = []
    for j, p in enumerate(parents):
        if p < 0:
            world.append(rot[..., j, :, :])
            pos.append(rest[..., j, :])
        else:
            off = (rest[..., j, :] - rest[..., p, :])[..., None]
            pos.append(pos[p] + (world[p] @ off)[..., 0])
            world.append(world[p] @ rot[..., j, :, :])
    return torch.stack(pos, dim=-2), torch.stack(world, dim=-3)
