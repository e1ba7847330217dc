"""Linear blend skinning, batched in torch (the maths of ``smplx.lbs``).

Forward kinematics and rotation conversions are in ``core.geometry`` (numpy, with torch twins in
``core.geometry.torch_ops``). Shapes: B batch, J joints, V vertices.

``posed_joints`` gives a motion's joints (what ``BodyModel.forward`` returns beside the vertices)
without skinning a single vertex, ``WINDOW`` frames at a time: memory stays a constant however long
the take (posing the mesh of a 10-minute take at once needed ~20 GB).
"""
from __future__ import annotations

import torch

from ..geometry.torch_ops import axis_angle_to_matrix, forward_kinematics

WINDOW = 256  # frames posed at once by the windowed steps (a few MB each, whatever the take's length)


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


def posed_joints(body, betas, rotations, transl=None, window: int = WINDOW) -> torch.Tensor:
    """(T,24,3) posed joints of ``body`` with one shape ``betas`` (10,) for ``rotations`` (T,24,3)
    axis-angle or (T,24,3,3) and ``transl`` (T,3): exactly ``body.forward(betas, rotations,
    transl).joints`` (same float32 arithmetic), computed ``window`` frames at a time, no vertices."""
    rot = torch.as_tensor(rotations, dtype=torch.float32)
    rest = body.rest_joints(torch.as_tensor(betas, dtype=torch.float32).reshape(1, -1))  # (1,24,3)
    t = None if transl is None else torch.as_tensor(transl, dtype=torch.float32).reshape(-1, 3)
    out = []
    for s in range(0, rot.shape[0], window):
        r = as_rotation_matrices(rot[s:s + window])
        pos, _ = forward_kinematics(r, rest.expand(r.shape[0], -1, -1), body.parents)
        out.append(pos if t is None else pos + t[s:s + window, None])
    return torch.cat(out, 0) if out else torch.zeros(0, rest.shape[1], 3)
