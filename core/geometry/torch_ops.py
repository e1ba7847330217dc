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
    base = [p if p >= 0 else j for j, p in enumerate(parents)]
    is_child = torch.tensor([[float(p >= 0)] for p in parents], dtype=rest_joints.dtype, device=rest_joints.device)
    offsets = rest_joints - rest_joints[..., base, :] * is_child   # a root keeps its position
    return forward_kinematics_offsets(rotations, offsets, parents)


def forward_kinematics_offsets(rotations: torch.Tensor, offsets: torch.Tensor, parents,
                               transl: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """``forward_kinematics`` from bone offsets (``fk.bone_offsets``: each joint relative to its
    parent, a root at its position), with the roots moved by ``transl`` (..., 3). J may be fewer
    than the offsets' joints (the first J are used: IK poses the 22 body joints of a 24-joint
    rest). Returns posed joints (..., J, 3) and world rotations (..., J, 3, 3)."""
    parents = [int(p) for p in parents]
    shape = torch.broadcast_shapes(rotations.shape[:-3], offsets.shape[:-2])
    one_skeleton = offsets.dim() == 2  # (J, 3): matrix-vector products, the fast path IK takes
    world: list[torch.Tensor] = []
    pos: list[torch.Tensor] = []
    rots, offs = rotations.unbind(-3), offsets.unbind(-2)
    for j, rot in enumerate(rots):
        p, off = parents[j], offs[j]
        if p < 0:
            world.append(rot.expand(*shape, 3, 3))
            pos.append(off.expand(*shape, 3) if transl is None else off + transl)
        elif one_skeleton:
            pos.append(pos[p] + world[p] @ off)
            world.append(world[p] @ rot)
        else:
            pos.append(pos[p] + (world[p] @ off[..., None])[..., 0])
            world.append(world[p] @ rot)
    return torch.stack(pos, dim=-2), torch.stack(world, dim=-3)


def _unit(v: torch.Tensor, eps: float = 1e-9) -> torch.Tensor:
    return v / torch.linalg.norm(v, dim=-1, keepdim=True).clamp_min(eps)


def orthonormal_frame(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """(..., 3, 3) frame with columns [a, b made orthogonal to a, a x b] (unit); for b parallel to
    a any perpendicular is used. ``rotations.orthonormal_frame`` in numpy."""
    e1 = _unit(a)
    b = b - (b * e1).sum(-1, keepdim=True) * e1
    alt = torch.where(e1[..., :1].abs() < 0.9, torch.tensor([1.0, 0, 0], dtype=a.dtype, device=a.device),
                      torch.tensor([0, 1.0, 0], dtype=a.dtype, device=a.device))
    alt = alt - (alt * e1).sum(-1, keepdim=True) * e1
    bad = torch.linalg.norm(b, dim=-1, keepdim=True) < 1e-7
    e2 = _unit(torch.where(bad, alt, b))
    return torch.stack([e1, e2, torch.cross(e1, e2, dim=-1)], dim=-1)


def rotation_between(u: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Shortest-arc rotations (..., 3, 3) taking directions u to v (any length); opposite
    directions give a half turn about an axis perpendicular to u. ``rotations.rotation_between``
    in numpy."""
    a, b = _unit(u), _unit(v)
    w = torch.cross(a, b, dim=-1)
    c = (a * b).sum(-1)
    x, y, z = w.unbind(-1)
    zero = torch.zeros_like(x)
    k = torch.stack([zero, -z, y, z, zero, -x, -y, x, zero], -1).reshape(*w.shape[:-1], 3, 3)
    eye = torch.eye(3, dtype=a.dtype, device=a.device).expand(k.shape)
    rot = eye + k + (k @ k) / (1 + c).clamp_min(1e-6)[..., None, None]
    anti = c < -1 + 1e-6
    if anti.any():
        p = orthonormal_frame(a, torch.ones_like(a))[..., 1]
        half = 2 * p[..., :, None] * p[..., None, :] - eye
        rot = torch.where(anti[..., None, None], half, rot)
    return rot
