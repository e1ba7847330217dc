"""Motion tokens + body shape -> a Motion on the body model (the last step of generation,
retargeting and re-decoding for a new body)."""
from __future__ import annotations

import numpy as np
import torch

from ..body.skeleton import FOOT_JOINTS
from ..constants import FPS
from ..errors import ShapeMoveError
from ..scene.motion_file import Motion



def check_betas(betas) -> np.ndarray:
    b = np.asarray(betas, dtype=np.float32).reshape(-1)
    if b.shape != (10,) or not np.isfinite(b).all():
        raise ShapeMoveError(f"betas must be 10 finite values, got shape {b.shape}")
    return b


def decode_tokens(codes: list[int], vae, body, betas, ik_refine_iters: int = 10, prompt: str | None = None) -> Motion:
    """Motion tokens + betas (10,) -> Motion on ``body``: SA-VAE ``decode_long`` with the body's
    shape, joints from the features, lowest foot on the floor, IK onto the body."""
    from ..body.ik import solve_ik
    from ..geometry.rotations import matrix_to_axis_angle
    from ..motion.features import joints_from_features

    if not codes:
        raise ShapeMoveError("no motion tokens to decode")
    b = torch.as_tensor(check_betas(betas))[None]
    with torch.no_grad():
        idx = torch.as_tensor(codes, dtype=torch.long)[None]
        feats = vae.denormalize(vae.decode_long(vae.quantizer.indices_to_codes(idx), b))[0]
        joints = joints_from_features(feats.double()).float().numpy()
        rest = body.rest_joints(b)[0].numpy()
    joints[..., 1] -= joints[:, FOOT_JOINTS, 1].min()
    ik = solve_ik(joints, rest, refine_iters=ik_refine_iters)
    poses = matrix_to_axis_angle(ik.rotations).astype(np.float32)
    m = Motion(joints=joints, betas=b[0].numpy(), poses=poses, transl=np.asarray(ik.transl, np.float32),
               fps=float(FPS), body_model=body.name, prompt=prompt, tokens=np.asarray(codes, np.int16),
               features=feats.numpy().astype(np.float32))
    m.ik_error_cm = float(ik.mean_error_cm)
    return m
