"""Linear blend skinning, batched in torch (the maths of ``smplx.lbs``).

Forward kinematics and rotation conversions are in ``core.geometry`` (numpy, with torch twins in
``core.geometry.torch_ops``). Shapes: B batch, J joints, V vertices.
"""
from __future__ import annotations

import torch

from ..geometry.torch_ops import axis_angle_to_matrix


def as_rotation_matrices(rotations: torch.Tensor) -> torch.Tensor:
    """Accept (B,J,3) axis-angle or (B,J,3,3) matrices; return (B,J,3,3) matrices."""
    if rotations.dim() == 4 and rotations.shape[-2:] == (3, 3):
        return rotations
    if rotations.dim() == 3 and rotations.shape[-1] == 3:
        return axis_angle_to_matrix(rotations)
    raise ValueError(f"rotations must be (B,J,3) axis-angle or (B,J,3,3) matrices, got {tuple(rotations.shape)}")


def skinning_transforms(world_rotations: torch.Tensor, joints: torch.Tensor, rest_joints: torch.Tensor) -> torch.Tensor:
    """World rotations (B,J,3,3) and posed joints (B,J,3) from ``forward_kinematics`` ->
    (B,J,4,4) transforms that move rest-pose vertices (x -> R (x - rest_joint) + joint)."""
    out = torch.zeros(*world_rotations.shape[:-2], 4, 4, dtype=world_rotations.dtype, device=world_rotations.device)
    out[..., :3, :3] = world_rotations
    out[..., :3, 3] = joints - (world_rotations @ rest_joints[..., None]).squeeze(-1)
    out[..., 3, 3] = 1
    return out


def linear_blend_skinning(vertices: torch.Tensor, weights: torch.Tensor, transforms: torch.Tensor) -> torch.Tensor:
    """vertices (B,V,3) rest pose, weights (V,J), transforms (B,J,4,4) from ``skinning_transforms``."""
    T = torch.einsum("vj,bjmn->bvmn", weights, transforms)
    return (T[..., :3, :3] @ vertices[..., None]).squeeze(-1) + T[..., :3, 3]
