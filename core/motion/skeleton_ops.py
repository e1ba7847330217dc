"""Whole-clip skeleton operations on 22-joint motions: floor, facing direction, leg length, canonical pose.

Joints are (T, 22, 3) in metres, Y up, SMPL order (``core/body/skeleton.py``). The facing
direction is HumanML3D's: ``across = (r_hip - l_hip) + (r_shoulder - l_shoulder)`` and
``forward = cross(+Y, across)``, so a body in the rest pose (left at +X) faces +Z.
"""
from __future__ import annotations

import numpy as np
from ..body.skeleton import FACE_JOINTS
from ..errors import ShapeMoveError
from ..geometry.rotations import yaw_matrix


def check_joints(joints) -> np.ndarray:
    """Validate (T, J>=22, 3) positions; return the first 22 joints as float64."""
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim != 3 or joints.shape[1] < 22 or joints.shape[2] != 3:
        raise ShapeMoveError(f"joints must be (frames, 22, 3) positions, got shape {joints.shape}")
    if joints.shape[0] < 2:
        raise ShapeMoveError(f"a motion needs at least 2 frames, got {joints.shape[0]}")
    if not np.isfinite(joints).all():
        raise ShapeMoveError("joints contain NaN or infinite values")
    return joints[:, :22]


def floor_height(joints: np.ndarray) -> float:
    """Lowest joint height over the whole clip (HumanML3D's floor: min over all joints, frames)."""
    return float(np.asarray(joints)[..., 1].min())


def facing_directions(joints: np.ndarray) -> np.ndarray:
    """(T, 22, 3) -> (T, 3) unit horizontal forward directions (y = 0)."""
    r_hip, l_hip, r_sh, l_sh = FACE_JOINTS
    across = (joints[:, r_hip] - joints[:, l_hip]) + (joints[:, r_sh] - joints[:, l_sh])
    forward = np.cross(np.array([0.0, 1.0, 0.0]), across)  # = (across_z, 0, -across_x)
    norm = np.linalg.norm(forward, axis=-1, keepdims=True)
    if (norm < 1e-9).any():
        bad = int(np.argmax(norm[:, 0] < 1e-9))
        raise ShapeMoveError(f"cannot tell which way the body faces at frame {bad} "
                             "(hips and shoulders are vertical or coincide)")
    return forward / norm


def leg_length(joints) -> float:
    """The leg's length of (T, 22, 3) joints: hip to knee to ankle, both legs' mean, the median over
    the frames (at least 1 mm)."""
    j = np.asarray(joints, dtype=np.float64)
    seg = lambda a, b: np.linalg.norm(j[:, a] - j[:, b], axis=-1)  # noqa: E731
    return float(max(np.median((seg(1, 4) + seg(4, 7) + seg(2, 5) + seg(5, 8)) / 2), 1e-3))


def heading_angles(forward: np.ndarray) -> np.ndarray:
    """(T, 3) forward directions -> (T,) yaw angles, 0 for +Z, +pi/2 for +X."""
    return np.arctan2(forward[:, 0], forward[:, 2])


def gaussian_smooth(x: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian filter along axis 0 with 'nearest' edges, truncated at 4 sigma: the same numbers as
    ``scipy.ndimage.gaussian_filter1d(x, sigma, axis=0, mode="nearest")`` without needing scipy
    (Blender ships numpy only)."""
    radius = int(4.0 * sigma + 0.5)
    offsets = np.arange(-radius, radius + 1)
    weights = np.exp(-0.5 * (offsets / sigma) ** 2)
    weights /= weights.sum()
    index = np.clip(np.arange(len(x))[:, None] + offsets[None, :], 0, len(x) - 1)
    return np.einsum("tk,tk...->t...", np.broadcast_to(weights, index.shape), x[index])


def smooth_directions(forward: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian-smooth (T, 3) directions over time (HumanML3D: sigma 20 frames, 'nearest' edges)
    and renormalise. Frames whose smoothed vector vanishes (a spin faster than the window) keep
    their raw direction."""
    if sigma <= 0:
        return forward
    smooth = gaussian_smooth(forward, sigma)
    norm = np.linalg.norm(smooth, axis=-1, keepdims=True)
    ok = norm > 1e-6
    return np.where(ok, smooth / np.where(ok, norm, 1.0), forward)


def canonicalize(joints, keep_height: bool = False) -> np.ndarray:
    """Put a clip in HumanML3D's canonical place (no skeleton retarget).

    (T, 22, 3) metres -> (T, 22, 3) float64: the floor (lowest joint over the clip) at y = 0, the
    first frame's root at x = z = 0, and the first frame facing +Z (rotation about Y).
    ``keep_height``: leave the heights as given (a clip already grounded on its mesh's soles,
    whose lowest joint is above the floor).
    """
    joints = check_joints(joints).copy()
    if not keep_height:
        joints[..., 1] -= floor_height(joints)
    joints[..., [0, 2]] -= joints[0, 0, [0, 2]]
    theta0 = heading_angles(facing_directions(joints[:1]))[0]
    rot = yaw_matrix(-theta0)
    return joints @ rot.T
