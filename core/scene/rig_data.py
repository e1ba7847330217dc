"""Everything the Blender scene needs from a BodyModel and a motion, in Blender (Z-up) axes.

``RigData`` is plain numpy (float64, metres) so the bpy side only copies arrays into datablocks.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body.body_arrays import rest_joints_for
from ..body.skeleton import JOINT_NAMES, PARENTS
from ..errors import ShapeMoveError
from ..geometry.rotations import axis_angle_to_matrix
from .axes import Y_UP_TO_Z_UP, points_to_z_up, rotations_to_z_up
from .bones import BoneLayout, bone_layout
from .shape_keys import shape_key_coords


@dataclass
class RigData:
    body_model: str
    joint_names: list
    parents: np.ndarray          # (24,)
    v_template: np.ndarray       # (V,3) Z-up, the Basis shape key
    key_coords: np.ndarray       # (10,V,3) Z-up, shape key "beta_i" = template + shapedirs[..., i]
    faces: np.ndarray            # (F,3) int
    skin_weights: np.ndarray     # (V,24)
    joint_template: np.ndarray   # (24,3) Z-up rest joints at betas = 0
    joint_shapedirs: np.ndarray  # (24,3,10) Z-up
    betas: np.ndarray            # (10,)
    bones: BoneLayout            # bones for the rest joints at ``betas``


def _np(t) -> np.ndarray:
    return t.detach().cpu().numpy().astype(np.float64) if hasattr(t, "detach") else np.asarray(t, dtype=np.float64)


def rig_data(body, betas) -> RigData:
    """body: a BodyModel; betas (10,) -> RigData in Z-up with bones placed for ``betas``."""
    betas = np.asarray(betas, dtype=np.float64).reshape(-1)
    if betas.shape != (body.num_betas,):
        raise ShapeMoveError(f"betas must have {body.num_betas} values, got {betas.shape[0]}")
    if not np.isfinite(betas).all():
        raise ShapeMoveError("betas contain NaN or infinite values")
    template = points_to_z_up(_np(body.v_template))
    dirs = np.einsum("ck,vkb->vcb", Y_UP_TO_Z_UP, _np(body.shapedirs))
    jt = points_to_z_up(_np(body.joint_template))
    jd = np.einsum("ck,jkb->jcb", Y_UP_TO_Z_UP, _np(body.joint_shapedirs))
    return RigData(
        body_model=str(body.name), joint_names=list(JOINT_NAMES), parents=PARENTS.copy(),
        v_template=template, key_coords=shape_key_coords(template, dirs),
        faces=np.asarray(body.faces, dtype=np.int64), skin_weights=np.asarray(body.skin_weights, dtype=np.float64),
        joint_template=jt, joint_shapedirs=jd, betas=betas,
        bones=bone_layout(rest_joints_for(jt, jd, betas)),
    )


def motion_channels_z_up(poses, transl) -> tuple[np.ndarray, np.ndarray]:
    """poses (T,24,3) axis-angle (or (T,24,3,3)) Y-up, transl (T,3) Y-up ->
    local rotation matrices (T,24,3,3) and root offsets (T,3) in Z-up armature axes."""
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim == 3 and p.shape[-1] == 3:
        rot = axis_angle_to_matrix(p)
    elif p.ndim == 4 and p.shape[-2:] == (3, 3):
        rot = p
    else:
        raise ShapeMoveError(f"poses must be (T,24,3) axis-angle or (T,24,3,3), got {p.shape}")
    return rotations_to_z_up(rot), points_to_z_up(transl)
