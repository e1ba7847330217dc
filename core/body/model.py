"""The one body-model interface everything downstream uses (OpenBody, SMPL family).

A body model is a linear shape space (template + shapedirs . betas), a joint regressor that is
linear in the shaped vertices, the SMPL 24-joint tree and LBS weights. Subclasses only fill the
arrays; the maths lives here and in ``kinematics``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..constants import NUM_BETAS
from ..geometry.torch_ops import forward_kinematics
from .kinematics import as_rotation_matrices, linear_blend_skinning, skinning_transforms
from .skeleton import JOINT_NAMES, PARENTS



@dataclass
class BodyOutput:
    vertices: torch.Tensor  # (B,V,3) metres, Y up
    joints: torch.Tensor    # (B,24,3) SMPL order


class BodyModel(torch.nn.Module):
    """Arrays (registered as buffers, float32):
    v_template (V,3), shapedirs (V,3,10), j_regressor (24,V), skin_weights (V,24), faces (F,3) int.
    ``name`` identifies the model (stored in checkpoints so a mismatch is caught).
    """

    name: str = "body"
    joint_names = JOINT_NAMES
    num_betas = NUM_BETAS

    def __init__(self, v_template, shapedirs, j_regressor, skin_weights, faces, name: str | None = None):
        super().__init__()
        f32 = lambda a: torch.as_tensor(np.asarray(a), dtype=torch.float32)  # noqa: E731
        self.register_buffer("v_template", f32(v_template))
        sd = f32(shapedirs)[..., :NUM_BETAS]
        if sd.shape[-1] < NUM_BETAS:  # pad a smaller shape space with zeros
            sd = torch.cat([sd, sd.new_zeros(*sd.shape[:-1], NUM_BETAS - sd.shape[-1])], -1)
        self.register_buffer("shapedirs", sd)
        self.register_buffer("j_regressor", f32(j_regressor))
        self.register_buffer("skin_weights_t", f32(skin_weights))
        self.faces = np.asarray(faces, dtype=np.int64)
        self.parents = PARENTS.copy()
        if name:
            self.name = name
        # joints are linear in betas: J(b) = J0 + Jdirs . b
        self.register_buffer("joint_template", self.j_regressor @ self.v_template)
        self.register_buffer("joint_shapedirs", torch.einsum("jv,vcb->jcb", self.j_regressor, self.shapedirs))

    # -- facts ---------------------------------------------------------------------------------
    @property
    def skin_weights(self) -> np.ndarray:
        return self.skin_weights_t.numpy()

    @property
    def num_vertices(self) -> int:
        return int(self.v_template.shape[0])

    # -- shape ---------------------------------------------------------------------------------
    def _betas(self, betas, batch: int | None = None) -> torch.Tensor:
        if betas is None:
            return torch.zeros(batch or 1, NUM_BETAS)
        b = torch.as_tensor(betas, dtype=torch.float32)
        if b.dim() == 1:
            b = b[None]
        if b.shape[-1] != NUM_BETAS:
            raise ValueError(f"betas must have {NUM_BETAS} values, got {b.shape[-1]}")
        return b

    def rest_vertices(self, betas=None) -> torch.Tensor:
        b = self._betas(betas)
        return self.v_template + torch.einsum("vcb,nb->nvc", self.shapedirs, b)

    def rest_joints(self, betas=None) -> torch.Tensor:
        """(B,24,3) joint positions of the rest pose for the given betas (linear in betas)."""
        b = self._betas(betas)
        return self.joint_template + torch.einsum("jcb,nb->njc", self.joint_shapedirs, b)

    # -- pose ----------------------------------------------------------------------------------
    def pose_offsets(self, rotmats: torch.Tensor) -> torch.Tensor | None:
        """(B,V,3) pose-dependent vertex offsets added before skinning (none for a plain LBS model;
        the SMPL family's pose correctives)."""
        return None

    def forward(self, betas=None, rotations=None, transl=None) -> BodyOutput:
        """betas (B,10); rotations (B,24,3) axis-angle or (B,24,3,3) local; transl (B,3)."""
        if rotations is None:
            B = 1 if betas is None else self._betas(betas).shape[0]
            rotmats = torch.eye(3).expand(B, 24, 3, 3)
        else:
            rotmats = as_rotation_matrices(torch.as_tensor(rotations, dtype=torch.float32))
        B = rotmats.shape[0]
        b = self._betas(betas, B)
        if b.shape[0] == 1 and B > 1:
            b = b.expand(B, -1)
        verts = self.rest_vertices(b)
        offsets = self.pose_offsets(rotmats)
        if offsets is not None:
            verts = verts + offsets
        joints_rest = self.rest_joints(b)
        posed_joints, world = forward_kinematics(rotmats, joints_rest, self.parents)
        verts = linear_blend_skinning(verts, self.skin_weights_t, skinning_transforms(world, posed_joints, joints_rest))
        if transl is not None:
            t = torch.as_tensor(transl, dtype=torch.float32).reshape(-1, 1, 3)
            verts = verts + t
            posed_joints = posed_joints + t
        return BodyOutput(vertices=verts, joints=posed_joints)
