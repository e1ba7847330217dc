"""Change the frame rate of a clip: linear interpolation of joint positions, slerp of rotations."""
from __future__ import annotations

import numpy as np

from ..errors import ShapeMoveError
from ..geometry.rotations import matrix_to_quaternion, quaternion_to_matrix, slerp


def sample_times(num_frames: int, src_fps: float, dst_fps: float) -> np.ndarray:
    """Fractional source frame indices of the output frames: t_k = k * src/dst for every k whose time
    lies inside the clip (the first output frame is the first input frame)."""
    if not (src_fps > 0 and dst_fps > 0):
        raise ShapeMoveError(f"frame rates must be positive (got {src_fps} -> {dst_fps})")
    if num_frames < 1:
        raise ShapeMoveError("cannot resample an empty clip")
    step = src_fps / dst_fps
    n = int(np.floor((num_frames - 1) / step + 1e-9)) + 1
    return np.arange(n) * step


def resample_positions(x: np.ndarray, src_fps: float, dst_fps: float = 20.0) -> np.ndarray:
    """(T,...) positions at src_fps -> (T',...) at dst_fps by linear interpolation in time."""
    x = np.asarray(x, dtype=np.float64)
    if abs(src_fps - dst_fps) < 1e-9:
        return x.copy()
    t = sample_times(len(x), src_fps, dst_fps)
    i0 = np.minimum(np.floor(t).astype(np.int64), len(x) - 1)
    i1 = np.minimum(i0 + 1, len(x) - 1)
    w = (t - i0).reshape(-1, *([1] * (x.ndim - 1)))
    return (1 - w) * x[i0] + w * x[i1]


def resample_rotations(R: np.ndarray, src_fps: float, dst_fps: float = 20.0) -> np.ndarray:
    """(T,J,3,3) local rotations -> (T',J,3,3) at dst_fps by slerp between neighbouring frames."""
    if abs(src_fps - dst_fps) < 1e-9:
        return np.array(R, dtype=np.float64)
    t = sample_times(len(R), src_fps, dst_fps)
    i0 = np.minimum(np.floor(t).astype(np.int64), len(R) - 1)
    i1 = np.minimum(i0 + 1, len(R) - 1)
    q = matrix_to_quaternion(R)
    w = np.broadcast_to((t - i0)[:, None], (len(t), R.shape[1]))
    return quaternion_to_matrix(slerp(q[i0], q[i1], w))
