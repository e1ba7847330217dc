"""A path as the feet walk it: a polyline of [x, z] points resampled by arc length, and a joint
track put onto it (``follow_track``): the track's course is split into the distance travelled
s(t) and its heading, and the body, relative to both, is put down at the line's point at the same
distance, turned to the line's tangent there. ``path_follow`` (a user's path) and ``course_walk``
(a circle the words name) walk their lines with it.

Paths: a JSON list of [x, z] points in metres (Y up, as the motion file). The polyline is
resampled every ``STEP`` m and its tangent smoothed over ``TURN_RADIUS`` m, so a corner becomes a
short arc the feet can follow.
"""
from __future__ import annotations

import numpy as np

from ..errors import ShapeMoveError
from ..motion.skeleton_ops import gaussian_smooth
from .track import Track, headings, root_centre, rotate_y, travel

STEP = 0.02          # m between resampled path points
TURN_RADIUS = 0.25   # m (Gaussian sigma along the path) over which a corner's tangent turns
MIN_LENGTH = 0.2     # m
MAX_LENGTH = 1000.0  # m
MIN_SPEED = 0.15     # m/s: a motion slower than this does not travel (a wave, a sit)
MAX_POINTS = 100_000
FORWARD_WITHIN = np.radians(60)   # a gait travelling this close to the way it faces goes forward


def check_path(points) -> np.ndarray:
    """A list of [x, z] pairs -> (N,2) float64; ShapeMoveError when it is not a usable path."""
    try:
        p = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise ShapeMoveError("a path must be a list of [x, z] number pairs (metres)") from None
    if p.ndim != 2 or p.shape[1] != 2 or not 2 <= len(p) <= MAX_POINTS:
        raise ShapeMoveError(f"a path must be a list of 2 to {MAX_POINTS} [x, z] pairs, got shape {p.shape}")
    if not np.isfinite(p).all():
        raise ShapeMoveError("a path's points must be finite numbers")
    keep = np.r_[True, np.linalg.norm(np.diff(p, axis=0), axis=1) > 1e-6]
    p = p[keep]
    length = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) if len(p) > 1 else 0.0
    if not MIN_LENGTH <= length <= MAX_LENGTH:
        raise ShapeMoveError(f"a path must be {MIN_LENGTH} to {MAX_LENGTH:g} m long, this one is {length:.2f} m")
    return p


class Polyline:
    """A path resampled by arc length: ``point(s)`` and ``heading(s)`` (yaw of the tangent,
    0 along +Z, +pi/2 along +X) at distances ``s`` from its start."""

    def __init__(self, points):
        p = check_path(points)
        seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
        cum = np.r_[0.0, np.cumsum(seg)]
        self.length = float(cum[-1])
        self.s = np.linspace(0.0, self.length, max(2, int(np.ceil(self.length / STEP)) + 1))
        self.xz = np.stack([np.interp(self.s, cum, p[:, 0]), np.interp(self.s, cum, p[:, 1])], axis=1)
        tangent = np.gradient(self.xz, axis=0)
        tangent = gaussian_smooth(tangent / np.maximum(np.linalg.norm(tangent, axis=1, keepdims=True), 1e-12),
                                  TURN_RADIUS / (self.s[1] - self.s[0]))
        self.yaw = np.unwrap(np.arctan2(tangent[:, 0], tangent[:, 1]))

    def point(self, s) -> np.ndarray:
        """(N,2) points at distances ``s``; beyond the end, along the last tangent."""
        s = np.asarray(s, np.float64)
        inside = np.clip(s, 0.0, self.length)
        xz = np.stack([np.interp(inside, self.s, self.xz[:, 0]), np.interp(inside, self.s, self.xz[:, 1])], axis=-1)
        extra = (s - inside)[..., None]
        return xz + extra * np.stack([np.sin(self.yaw[-1]), np.cos(self.yaw[-1])])

    def heading(self, s) -> np.ndarray:
        return np.interp(np.clip(s, 0.0, self.length), self.s, self.yaw)

    def nearest(self, xz) -> tuple[np.ndarray, np.ndarray]:
        """(distance (N,), tangent yaw (N,)) of points (N,2) to the resampled path."""
        xz = np.asarray(xz, np.float64)
        d = np.linalg.norm(xz[:, None] - self.xz[None], axis=-1)
        i = d.argmin(1)
        return d[np.arange(len(xz)), i], self.yaw[i]


def gait_offset(joints) -> float:
    """The way a track travels less the way it faces, snapped to a quarter turn: 0 for a gait going
    forward (anything within ``FORWARD_WITHIN``), pi for one going backwards, +-pi/2 for a sidestep
    (yaw, travel weighted)."""
    return _offset(root_centre(joints), headings(joints))


def _offset(centre: np.ndarray, heading: np.ndarray) -> float:
    """``gait_offset`` from the track's smoothed root path (T, 2) and heading (T,)."""
    v = np.diff(centre, axis=0)
    w = np.linalg.norm(v, axis=1)
    if w.sum() < 1e-9:
        return 0.0
    rel = np.arctan2(v[:, 0], v[:, 1]) - heading[1:]
    mean = float(np.arctan2((w * np.sin(rel)).sum(), (w * np.cos(rel)).sum()))
    return 0.0 if abs(mean) < FORWARD_WITHIN else float(np.round(mean / (np.pi / 2)) * np.pi / 2)


def follow_track(track: Track, line: Polyline, crop: bool = True) -> Track:
    """The track's body moved onto ``line`` (see the module doc), going along it the way it went
    (``gait_offset``: a backward walk faces away from the way the line goes); ``crop``: frames after
    the one that reaches the end of the path are dropped."""
    J = track.joints
    h = headings(J)
    c = root_centre(J)
    s = travel(J)
    local = J.copy()
    local[..., 0] -= c[:, None, 0]
    local[..., 2] -= c[:, None, 1]
    local = rotate_y(local, -h)
    xz = line.point(s)
    out = rotate_y(local, line.heading(s) - _offset(c, h))
    out[..., 0] += xz[:, None, 0]
    out[..., 2] += xz[:, None, 1]
    n = len(J)
    if crop:
        reached = np.flatnonzero(s >= line.length)
        n = int(reached[0]) + 1 if len(reached) else n
    return Track(out[:n], track.contacts[:n])
