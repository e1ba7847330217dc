"""Change the frame rate of a clip: linear interpolation of joint positions, slerp of rotations."""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from .limits import MAX_SECONDS, check_joint_frames
from ..geometry.rotations import matrix_to_quaternion, quaternion_to_matrix, slerp


def sample_times(num_frames: int, src_fps: float, dst_fps: float, joints: int = 1) -> np.ndarray:
    """Fractional source frame indices of the output frames: t_k = k * src/dst for every k whose time
    lies inside the clip (the first output frame is the first input frame). The clip's length and
    the output size (frames x ``joints``) are checked first: a slow frame rate in a small file
    must not ask for gigabytes."""
    if not (np.isfinite(src_fps) and np.isfinite(dst_fps) and src_fps > 0 and dst_fps > 0):
        raise ShapeMoveError(f"frame rates must be positive (got {src_fps} -> {dst_fps})")
    if num_frames < 1:
        raise ShapeMoveError("cannot resample an empty clip")
    seconds = (num_frames - 1) / src_fps
    if seconds > MAX_SECONDS:
        raise ShapeMoveError(f"the clip lasts {seconds:,.0f} s ({num_frames:,} frames at {src_fps:g} fps), longer "
                             f"than {MAX_SECONDS:.0f} s: wrong frame time in the file, or split the clip")
    step = src_fps / dst_fps
    n = int(np.floor((num_frames - 1) / step + 1e-9)) + 1
    check_joint_frames(n, joints, f"resampling {num_frames} frames from {src_fps:g} to {dst_fps:g} fps",
                       "result")
    return np.arange(n) * step


def resample_positions(x: np.ndarray, src_fps: float, dst_fps: float = FPS) -> np.ndarray:
    """(T,...) positions at src_fps -> (T',...) at dst_fps by linear interpolation in time."""
    x = np.asarray(x, dtype=np.float64)
    if abs(src_fps - dst_fps) < 1e-9:
        return x.copy()
    t = sample_times(len(x), src_fps, dst_fps, max(1, x[0].size // 3) if len(x) else 1)
    i0 = np.minimum(np.floor(t).astype(np.int64), len(x) - 1)
    i1 = np.minimum(i0 + 1, len(x) - 1)
    w = (t - i0).reshape(-1, *([1] * (x.ndim - 1)))
    return (1 - w) * x[i0] + w * x[i1]


def resample_rotations(R: np.ndarray, src_fps: float, dst_fps: float = FPS) -> np.ndarray:
    """(T,J,3,3) local rotations -> (T',J,3,3) at dst_fps by slerp between neighbouring frames."""
    if abs(src_fps - dst_fps) < 1e-9:
        return np.array(R, dtype=np.float64)
    t = sample_times(len(R), src_fps, dst_fps, R.shape[1] * 3)
    i0 = np.minimum(np.floor(t).astype(np.int64), len(R) - 1)
    i1 = np.minimum(i0 + 1, len(R) - 1)
    q = matrix_to_quaternion(R)
    w = np.broadcast_to((t - i0)[:, None], (len(t), R.shape[1]))
    return quaternion_to_matrix(slerp(q[i0], q[i1], w))
