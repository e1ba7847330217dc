"""Where a motion loops: the two frames a < b whose pose (relative to the root and heading) and
velocities are most alike (``best_cut``), the cut that ``loop.py`` makes a cycle of and that a
captured take repeats (``take_loop.py``)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from .track import headings, rotate_y

MIN_PERIOD = 1.0       # s: the shortest cycle (two steps of a walk)
VELOCITY_WEIGHT = 4.0  # a velocity mismatch of 1 cm/frame costs as much as 4 cm of pose
SEAM_SPEED = 1.0       # x its mean step: a joint faster than this at the seam frame is penalised
FAST_WEIGHT = 0.2      # m of cost per unit of speed ratio above SEAM_SPEED
EDGE = 2               # frames at each end of a decoded clip that a cut avoids


@dataclass
class Cut:
    start: int
    end: int
    cost: float   # m: mean joint distance of the two poses + weighted velocity distance

    @property
    def period(self) -> int:
        return self.end - self.start


def _local(joints, heading) -> tuple[np.ndarray, np.ndarray]:
    """Pose relative to the root's XZ and the heading, and backward velocity in that frame."""
    J = np.asarray(joints, np.float64)
    rel = J.copy()
    rel[..., [0, 2]] -= J[:, :1, [0, 2]]
    pose = rotate_y(rel, -heading)
    vel = np.zeros_like(J)
    vel[1:] = rotate_y(J[1:] - J[:-1], -heading[1:])
    return pose, vel


def best_cut(joints, fps: float = FPS, period: tuple[float, float] | None = None) -> Cut:
    """The frames a < b whose pose and velocity are most alike, b - a within ``period`` (s)
    (default: at least ``MIN_PERIOD`` and 40 % of the clip)."""
    J = np.asarray(joints, np.float64)
    T = len(J)
    lo, hi = period if period is not None else (max(MIN_PERIOD, 0.4 * T / fps), T / fps)
    lo_f, hi_f = max(2, int(round(lo * fps))), int(round(hi * fps))
    pose, vel = _local(J, headings(J))
    first, last = max(1, EDGE), T - 1 - EDGE
    idx = np.arange(first, last + 1)
    if len(idx) < 2 or idx[-1] - idx[0] < lo_f:
        raise ShapeMoveError(f"a {T / fps:.1f} s motion is too short for a loop of at least {lo:.1f} s")
    P, V = pose[idx], vel[idx]
    d = np.linalg.norm(P[:, None] - P[None], axis=-1).mean(-1) + \
        VELOCITY_WEIGHT * np.linalg.norm(V[:, None] - V[None], axis=-1).mean(-1)
    # the seam's step is the step into frame b: a frame where some joint moves much faster than
    # its mean (a swinging foot) would make the wrap look like a pop, so such ends cost more
    speed = np.linalg.norm(vel, axis=-1)                                  # (T,22)
    fast = np.maximum(speed / np.maximum(speed[1:].mean(0), 1e-4) - SEAM_SPEED, 0.0).max(1)
    d += FAST_WEIGHT * fast[idx][None, :]
    gap = idx[None] - idx[:, None]
    d[(gap < lo_f) | (gap > hi_f)] = np.inf
    i, j = np.unravel_index(np.argmin(d), d.shape)
    if not np.isfinite(d[i, j]):
        raise ShapeMoveError(f"no loop of {lo:.1f}..{hi:.1f} s fits in this {T / fps:.1f} s motion")
    return Cut(int(idx[i]), int(idx[j]), float(d[i, j]))
