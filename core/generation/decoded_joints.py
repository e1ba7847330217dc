"""The joints a generated motion is played from: the decoder's rotations posed on the body.

The SA-VAE writes each frame twice: as joint positions (the ``ric`` block, read by
``joints_from_features``) and as the local rotations of joints 1..21 (the ``rot6d`` block). The two
do not agree exactly (posed on the body, the rotations put the wrists and ankles 5-20 cm from the
decoded positions), and they do not carry the action equally: played from the positions alone (IK,
so the rotations follow the positions as they do in the training clips), the default model's
motions for the blind held-out paraphrases read as the asked action 50 % of the time on the
frequent actions (TMA judge); with the upper body posed from the decoded rotations, 68 % (70 %
lenient; docs/design-notes.md, Planting and retargeting).

The legs and the path stay the positions': they were trained with the foot and stability losses,
travel as fast as real clips of the same action and stride with the leg length. Posed from the
rotations too, the legs left the feet skating more (foot-vertex skate 32.9 -> 41.4 % on `eval
generate`) and the body less often dynamically stable (71.9 -> 47.1 %); the rotations' upper body
jitters more than the positions' (``plant.smooth_body`` takes it out: ``decode.motion_from_joints``).

``decoded_joints``: the pelvis, hips, knees, ankles, feet and spine1 where the positions put them;
spine2 and everything above it (spine, neck, head, collars, arms) posed with the decoded rotations
on the body (forward kinematics, the root turned as the rigid fit of the decoded pelvis, hips and
spine1), hung from the decoded spine1. Planting (``plant.plant_motion``) then lands the feet and
solves the rig's rotations from these joints.
"""
from __future__ import annotations

import numpy as np
import torch

from ..body.skeleton import JOINT_INDEX, NUM_BODY_JOINTS, PARENTS
from ..errors import ShapeMoveError
from ..geometry.rotations import rot6d_to_matrix
from ..geometry.torch_ops import forward_kinematics
from ..motion.features import FEATURE_DIM, feature_slices, joints_from_features

SPINE1 = JOINT_INDEX["spine1"]


def _below(joint: int, ancestor: int) -> bool:
    while joint >= 0:
        if joint == ancestor:
            return True
        joint = int(PARENTS[joint])
    return False


UPPER = [j for j in range(NUM_BODY_JOINTS) if _below(j, JOINT_INDEX["spine2"])]   # spine2 and all above it


def decoded_joints(features, body, betas) -> np.ndarray:
    """(T, 263) de-normalized features decoded for ``betas`` -> (T, 22, 3) float64 joints (metres,
    Y up, the features' canonical frame): the decoded positions of the pelvis, legs and spine1;
    above spine1, the body ``body`` with ``betas`` posed with the decoded local rotations (its
    root turned as the rigid fit of the decoded pelvis, hips and spine1, ``ik.fit_root``), moved
    so that its spine1 is the decoded one. The upper body's bones are the body's own."""
    from ..body.ik import fit_root

    f = features.double().numpy() if isinstance(features, torch.Tensor) else np.asarray(features, np.float64)
    if f.ndim != 2 or f.shape[1] != FEATURE_DIM or len(f) < 1 or not np.isfinite(f).all():
        raise ShapeMoveError(f"decoded features must be finite (T, {FEATURE_DIM}), got shape {f.shape}")
    positions = joints_from_features(f)
    b = torch.as_tensor(np.asarray(betas, np.float32).reshape(1, -1))
    with torch.no_grad():
        rest = body.rest_joints(b)[0].double()
        root, _ = fit_root(torch.as_tensor(positions), rest, PARENTS)
    local = rot6d_to_matrix(f[:, feature_slices["rot6d"]].reshape(len(f), NUM_BODY_JOINTS - 1, 6))
    rot = np.tile(np.eye(3), (len(f), rest.shape[0], 1, 1))
    rot[:, 0] = root.numpy()
    rot[:, 1:NUM_BODY_JOINTS] = local
    with torch.no_grad():
        posed, _ = forward_kinematics(torch.as_tensor(rot), rest[None].expand(len(f), -1, -1), body.parents)
    posed = posed[:, :NUM_BODY_JOINTS].numpy()
    out = positions.copy()
    out[:, UPPER] = posed[:, UPPER] - posed[:, [SPINE1]] + positions[:, [SPINE1]]
    return out
