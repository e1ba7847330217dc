"""The HumanML3D 263-dim motion representation (Guo et al. 2022), for 22-joint SMPL motions.

One row per frame pair (t, t+1); a clip of T frames gives T-1 rows::

    [0:1]     root_rot_vel  rotation of the root frame about Y from t to t+1, as HumanML3D stores
                            it: HALF the angle, sign of the world->root rotation, i.e.
                            -(heading[t+1] - heading[t]) / 2 (heading 0 = +Z, +pi/2 = +X)
    [1:3]     root_lin_vel  root (x, z) displacement t -> t+1 (metres/frame), in the root frame
                            of frame t+1
    [3:4]     root_y        root height at t (metres above the floor)
    [4:67]    ric           joints 1..21 relative to the root's (x, z), in the root frame of t
    [67:193]  rot6d         local rotations of joints 1..21 at t, 6D = first two COLUMNS
    [193:259] local_vel     displacement t -> t+1 of all 22 joints, in the root frame of t
    [259:263] contacts      left ankle, left foot, right ankle, right foot: 1 where the squared
                            displacement t -> t+1 (m^2) is below ``feet_thre``

Steps as HumanML3D's ``process_file`` WITHOUT its "uniform skeleton" retarget (a shape-aware
motion keeps its own body): floor (lowest joint over the clip) to y = 0, first frame's root to
x = z = 0, first frame turned to face +Z. The root frame of each frame is a rotation about Y
from the facing direction (``skeleton_ops``) Gaussian-smoothed over time (sigma 20 frames, as
HumanML3D's ``smooth_forward=True``); frame 0's root frame is the canonical frame itself
(identity), which is what ``recover_from_ric`` assumes, so features -> joints is exact.
Differences from the public HumanML3D code, on purpose: the facing uses (r_hip - l_hip) +
(r_sh - l_sh) everywhere (HumanML3D's ``inverse_kinematics_np`` swaps the hips, its issue #107);
root_rot_vel is wrapped so a heading crossing +-180 degrees is not a near full turn; the rotation
block holds SMPL-style local rotations (see ``local_rotations_from_joints``), not HumanML3D's
per-chain bone rotations.
"""
from __future__ import annotations

import numpy as np
import torch

from ..body.skeleton import FOOT_LEFT, FOOT_RIGHT, PARENTS
from ..errors import ShapeMoveError
from ..geometry.rotations import matrix_to_rot6d, rotation_between, yaw_matrix
from .skeleton_ops import canonicalize, facing_directions, heading_angles, smooth_directions

NUM_JOINTS = 22
FEATURE_DIM = 263

feature_slices = {
    "root_rot_vel": slice(0, 1),
    "root_lin_vel": slice(1, 3),
    "root_y": slice(3, 4),
    "ric": slice(4, 67),
    "rot6d": slice(67, 193),
    "local_vel": slice(193, 259),
    "contacts": slice(259, 263),
}



def height_column(joint: int) -> int:
    """The column of (T, 263) features holding joint ``joint``'s height above the floor (1..21: its
    y in ``ric``; the root's is ``root_y``)."""
    if not 1 <= joint < NUM_JOINTS:
        raise ShapeMoveError(f"features hold the heights of joints 1..{NUM_JOINTS - 1} in ric, not of joint {joint}")
    return feature_slices["ric"].start + 3 * (joint - 1) + 1


# HumanML3D's paramUtil.t2m_raw_offsets: unit rest direction of the bone ENDING at each joint
# (arms hanging down, feet and head pointing forward).
T2M_RAW_OFFSETS = np.array([
    [0, 0, 0], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, -1, 0], [0, 1, 0], [0, -1, 0],
    [0, -1, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1], [0, 1, 0], [1, 0, 0], [-1, 0, 0], [0, 0, 1],
    [0, -1, 0], [0, -1, 0], [0, -1, 0], [0, -1, 0], [0, -1, 0], [0, -1, 0]], dtype=np.float64)

_PARENTS = [int(p) for p in PARENTS[:NUM_JOINTS]]
# the bone that orients each joint: its first child (spine3 -> neck); leaves have none
_CHILD = {j: next((c for c in range(NUM_JOINTS) if _PARENTS[c] == j), None) for j in range(NUM_JOINTS)}


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi


def root_yaw(joints: np.ndarray, smooth_sigma: float = 20.0) -> np.ndarray:
    """Heading of each frame's root frame, (T, 22, 3) canonical joints -> (T,) radians.

    The facing direction smoothed over ``smooth_sigma`` frames; frame 0 is 0 (the canonical
    frame) as HumanML3D's recovery assumes."""
    theta = heading_angles(smooth_directions(facing_directions(joints), smooth_sigma))
    theta[0] = 0.0
    return theta


def local_rotations_from_joints(joints: np.ndarray, heading: np.ndarray, rest_joints=None) -> np.ndarray:
    """Swing-only local rotations estimated from positions, SMPL convention.

    joints (T, 22, 3); heading (T,) yaw of the root frame (the pelvis is given this rotation);
    rest_joints (22+, 3) rest-pose joints of the body (e.g. ``BodyModel.rest_joints(betas)``), or
    None for HumanML3D's ideal directions ``T2M_RAW_OFFSETS``. Returns (T, 22, 3, 3): for joint j
    the shortest-arc rotation, in its parent's frame, taking the rest direction of the bone to its
    first child onto the observed one (twist about the bone is unobservable and left at zero);
    leaves (feet, head, wrists) and the root entry are identity.
    """
    if rest_joints is None:
        rest_dir = {j: T2M_RAW_OFFSETS[c] for j, c in _CHILD.items() if c is not None}
    else:
        rest = np.asarray(rest_joints, dtype=np.float64)
        if rest.ndim != 2 or rest.shape[0] < NUM_JOINTS or rest.shape[1] != 3:
            raise ShapeMoveError(f"rest_joints must be (22, 3) positions, got shape {rest.shape}")
        rest_dir = {j: rest[c] - rest[j] for j, c in _CHILD.items() if c is not None}
    T = len(joints)
    local = np.broadcast_to(np.eye(3), (T, NUM_JOINTS, 3, 3)).copy()
    world = [yaw_matrix(heading)]
    for j in range(1, NUM_JOINTS):
        parent_world = world[_PARENTS[j]]
        c = _CHILD[j]
        if c is not None:
            bone = joints[:, c] - joints[:, j]
            bone_in_parent = np.einsum("tji,tj->ti", parent_world, bone)  # R^T v
            local[:, j] = rotation_between(rest_dir[j], bone_in_parent)
        world.append(parent_world @ local[:, j])
    return local


def features_from_joints(joints, local_rotations=None, feet_thre: float = 0.002,
                         rest_joints=None, smooth_sigma: float = 20.0, keep_height: bool = False) -> np.ndarray:
    """Joint positions -> HumanML3D features.

    joints (T, 22, 3) metres, Y up, 20 fps (extra joints beyond 22 are ignored);
    local_rotations (T, 22, 3, 3) rotations local to the parent in the SMPL rest frame (e.g. from
    our IK) or None to estimate swing rotations with ``local_rotations_from_joints`` (using
    ``rest_joints``); feet_thre threshold on the squared per-frame displacement (m^2).
    Returns (T-1, 263) float32. Only the 21 non-root rotations are stored, and those are unchanged
    by the canonicalising turn about Y, so given rotations are used as they are.
    ``keep_height``: keep the given heights instead of putting the lowest joint on y = 0 (for
    joints already grounded on the body's mesh: its soles are below the joints).
    """
    pos = canonicalize(joints, keep_height)
    T = len(pos)
    if local_rotations is not None:
        local_rotations = np.asarray(local_rotations, dtype=np.float64)
        if local_rotations.shape[:1] != (T,) or local_rotations.shape[1] < NUM_JOINTS \
                or local_rotations.shape[2:] != (3, 3):
            raise ShapeMoveError(f"local_rotations must be ({T}, 22, 3, 3) matrices, "
                                 f"got shape {local_rotations.shape}")
    heading = root_yaw(pos, smooth_sigma)
    to_root = yaw_matrix(-heading)                                     # world -> root frame, (T,3,3)

    rot_vel = -_wrap(np.diff(heading)) / 2.0
    root_step = pos[1:, 0] - pos[:-1, 0]
    lin_vel = np.einsum("tij,tj->ti", to_root[1:], root_step)[:, [0, 2]]
    root_y = pos[:-1, 0, 1]

    rel = pos.copy()
    rel[..., [0, 2]] -= pos[:, :1, [0, 2]]
    ric = np.einsum("tij,tkj->tki", to_root, rel)[:-1, 1:]

    if local_rotations is None:
        local_rotations = local_rotations_from_joints(pos, heading, rest_joints)
    rot6d = matrix_to_rot6d(local_rotations[:-1, 1:NUM_JOINTS])

    local_vel = np.einsum("tij,tkj->tki", to_root[:-1], pos[1:] - pos[:-1])

    speed2 = ((pos[1:] - pos[:-1]) ** 2).sum(-1)
    contacts = (speed2[:, FOOT_LEFT + FOOT_RIGHT] < feet_thre).astype(np.float64)

    out = np.concatenate([rot_vel[:, None], lin_vel, root_y[:, None], ric.reshape(T - 1, -1),
                          rot6d.reshape(T - 1, -1), local_vel.reshape(T - 1, -1), contacts], axis=-1)
    return out.astype(np.float32)


def posed_features(joints, rotations, contacts) -> np.ndarray:
    """(T-1,263) HumanML3D features of a motion on a body: (T,22,3) joints grounded on the mesh
    (heights kept as they are) with their local ``rotations`` (T,>=22,3,3), the 4 foot-contact
    channels holding ``contacts`` (T,4) of joints 7, 8, 10, 11. The dataset builder's features of
    a clip, and those of a motion generated by body part (what the rig plays)."""
    from .contacts import to_feature_order

    f = features_from_joints(joints, np.asarray(rotations)[:, :22], keep_height=True)
    f[:, feature_slices["contacts"]] = to_feature_order(np.asarray(contacts)[:-1]).astype(np.float32)
    return f


def motion_features(motion) -> np.ndarray:
    """``posed_features`` of a planted Motion: its posed joints, its poses as rotations, its
    contacts (what the rig plays, computed as the dataset builder computes a clip's)."""
    from ..geometry.rotations import axis_angle_to_matrix

    return posed_features(motion.joints, axis_angle_to_matrix(motion.poses), motion.contacts)


def _check_features(features):
    if features.shape[-1] != FEATURE_DIM or features.ndim < 2:
        raise ShapeMoveError(f"features must be (..., frames, {FEATURE_DIM}), got shape {tuple(features.shape)}")


def root_from_features(features: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Integrate the root: (..., T, 263) -> yaw (..., T) world->root angle (full angle, radians;
    0 at frame 0) and root positions (..., T, 3). Torch, differentiable (HumanML3D
    ``recover_root_rot_pos``)."""
    _check_features(features)
    half = torch.cumsum(features[..., :-1, 0], dim=-1)
    yaw = 2.0 * torch.cat([torch.zeros_like(half[..., :1]), half], dim=-1)
    c, s = torch.cos(yaw[..., 1:]), torch.sin(yaw[..., 1:])
    vx, vz = features[..., :-1, 1], features[..., :-1, 2]
    # root -> world is the rotation by -yaw about Y
    step_x = vx * c - vz * s
    step_z = vx * s + vz * c
    zero = torch.zeros_like(step_x[..., :1])
    root = torch.stack([torch.cat([zero, torch.cumsum(step_x, -1)], -1), features[..., 3],
                        torch.cat([zero, torch.cumsum(step_z, -1)], -1)], dim=-1)
    return yaw, root


def joints_from_features(features):
    """HumanML3D ``recover_from_ric``: (..., T, 263) -> (..., T, 22, 3) joint positions.

    Accepts torch (batched, differentiable, same dtype/device) or numpy (returns numpy of the
    input's float dtype). The result is the canonicalised clip (floor at 0, first root at x=z=0,
    first frame facing +Z)."""
    is_np = not isinstance(features, torch.Tensor)
    f = torch.as_tensor(np.asarray(features, dtype=np.float64)) if is_np else features
    yaw, root = root_from_features(f)
    ric = f[..., 4:67].unflatten(-1, (NUM_JOINTS - 1, 3))
    c, s = torch.cos(yaw)[..., None], torch.sin(yaw)[..., None]
    x = ric[..., 0] * c - ric[..., 2] * s + root[..., None, 0]
    z = ric[..., 0] * s + ric[..., 2] * c + root[..., None, 2]
    body = torch.stack([x, ric[..., 1], z], dim=-1)
    out = torch.cat([root[..., None, :], body], dim=-2)
    if is_np:
        dtype = np.asarray(features).dtype
        return out.numpy().astype(dtype if dtype.kind == "f" else np.float32)
    return out


def mean_std(features_list, feat_bias: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Normalisation statistics over clips, as HumanML3D's ``cal_mean_variance``.

    features_list: iterable of (T_i-1, 263) arrays. Mean: per-dimension mean over all frames.
    Std: per-dimension std over all frames, then each group of ``feature_slices`` replaced by the
    mean of its stds (so all 63 ric dims share one scale, etc.). ``feat_bias`` divides the stds of
    root_rot_vel, root_lin_vel, root_y and contacts (T2M's training-time weighting, opt.feat_bias
    = 5 there, making those dims 5x louder); HumanML3D's saved Std.npy uses 1 (the default).
    A group whose std is 0 (e.g. no contact ever seen) gets 1 so normalising stays finite.
    Returns (Mean, Std), float32 (263,).
    """
    arrays = [np.asarray(a, dtype=np.float64) for a in features_list]
    if not arrays:
        raise ShapeMoveError("mean_std needs at least one feature array")
    for i, a in enumerate(arrays):
        if a.ndim != 2 or a.shape[1] != FEATURE_DIM:
            raise ShapeMoveError(f"feature array {i} must be (frames, {FEATURE_DIM}), got {a.shape}")
        if not np.isfinite(a).all():
            raise ShapeMoveError(f"feature array {i} contains NaN or infinite values")
    data = np.concatenate(arrays, axis=0)
    mean = data.mean(axis=0)
    std = data.std(axis=0)
    for name, sl in feature_slices.items():
        group = std[sl].mean()
        if group <= 0:
            group = 1.0
        if name in ("root_rot_vel", "root_lin_vel", "root_y", "contacts"):
            group /= feat_bias
        std[sl] = group
    return mean.astype(np.float32), std.astype(np.float32)
