"""Along a path: a locomotion motion walks a polyline at its own speed, turning where it turns.

``follow_path(motion, body, path)``: the decoder's joint track is split into the root's smoothed
course (``track.root_centre``; its distance travelled s(t)) and heading (``track.headings``), and
the body relative to both (sway, hip swing and limbs kept). The body is then put down at the
path's point at the same distance s(t), turned to the path's tangent there; the contacts are
planted again (``track.plant``), so a stance foot stays on one point while the path turns under
the body. Without ``seconds`` the clip ends where the path ends (the motion must travel at least
that far: ``generate_along_path`` asks the model for a long enough motion); with it, the motion
keeps its length and goes on along the last tangent if it is longer than the path.

Paths: a JSON list of [x, z] points in metres (Y up, as the motion file). The polyline is
resampled every ``STEP`` m and its tangent smoothed over ``TURN_RADIUS`` m, so a corner becomes a
short arc the feet can follow.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from ..motion.skeleton_ops import facing_directions, gaussian_smooth, heading_angles
from ..scene.motion_file import Motion
from .track import Track, headings, plant, root_centre, rotate_y, track_of, travel

STEP = 0.02          # m between resampled path points
TURN_RADIUS = 0.25   # m (Gaussian sigma along the path) over which a corner's tangent turns
MIN_LENGTH = 0.2     # m
MAX_LENGTH = 1000.0  # m
MIN_SPEED = 0.15     # m/s: a motion slower than this does not travel (a wave, a sit)
MAX_POINTS = 100_000


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


def read_path(path) -> np.ndarray:
    """A path file (JSON list of [x, z] in metres) -> (N,2)."""
    path = Path(path)
    if not path.is_file():
        raise ShapeMoveError(f"path file not found: {path}")
    if path.stat().st_size > 16 * 2**20:
        raise ShapeMoveError(f"path file {path} is larger than 16 MiB")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ShapeMoveError(f"path file {path} is not valid JSON ({exc})") from None
    if isinstance(data, dict):
        data = data.get("points")
    return check_path(data)


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


def motion_speed(motion_or_joints, fps: float = FPS) -> float:
    """Mean speed (m/s) of the smoothed root along its own course."""
    joints = motion_or_joints.joints if isinstance(motion_or_joints, Motion) else motion_or_joints
    s = travel(joints)
    return float(s[-1] / max(len(s) - 1, 1) * fps)


def follow_track(track: Track, line: Polyline, crop: bool = True) -> Track:
    """The track's body moved onto ``line`` (see the module doc); ``crop``: frames after the
    one that reaches the end of the path are dropped."""
    J = track.joints
    h = headings(J)
    c = root_centre(J)
    s = travel(J)
    local = J.copy()
    local[..., 0] -= c[:, None, 0]
    local[..., 2] -= c[:, None, 1]
    local = rotate_y(local, -h)
    xz = line.point(s)
    out = rotate_y(local, line.heading(s))
    out[..., 0] += xz[:, None, 0]
    out[..., 2] += xz[:, None, 1]
    n = len(J)
    if crop:
        reached = np.flatnonzero(s >= line.length)
        n = int(reached[0]) + 1 if len(reached) else n
    return Track(out[:n], track.contacts[:n])


def follow_path(motion: Motion, body, path, crop: bool = True, ik_refine_iters: int = 10) -> Motion:
    """``motion`` walked along ``path`` ((N,2) [x, z] points or a ``Polyline``), feet re-planted."""
    line = path if isinstance(path, Polyline) else Polyline(path)
    v = motion_speed(track_of(motion).joints, motion.fps)
    if v < MIN_SPEED:
        raise ShapeMoveError(f"this motion travels {v:.2f} m/s: following a path needs a motion that moves "
                             "forward, e.g. 'a person walks forward'")
    out = plant(body, motion.betas, follow_track(track_of(motion), line, crop), ik_refine_iters, prompt=motion.prompt)
    if crop and travel(out.joints)[-1] < line.length - 0.25:
        out.warnings = [f"the motion ends {line.length - travel(out.joints)[-1]:.2f} m before the path's end"]
    return out


def generate_along_path(gen, req, path, progress=None, speed: float | None = None) -> Motion:
    """``req`` (a ``generate.Request``) walked along ``path``. Without ``req.seconds`` the length
    follows the path: a first motion measures the prompt's speed, and when it does not reach the
    end, a second one of the length the path needs (<= 60 s) replaces it. ``speed`` (0.5..2):
    the motion is played that much faster before it walks the path (``time_warp``)."""
    from .time_warp import time_warp

    line = path if isinstance(path, Polyline) else Polyline(path)
    fixed = req.seconds is not None
    motion = gen.generate_batch([req])[0]
    factor = 1.0 if speed is None else float(speed)
    v = motion_speed(track_of(motion).joints, motion.fps) * factor
    if v < MIN_SPEED:
        raise ShapeMoveError(f"{req.prompt!r} travels {v:.2f} m/s: following a path needs a prompt that moves "
                             "forward, e.g. 'a person walks forward'")
    if not fixed and travel(track_of(motion).joints)[-1] < line.length:
        need = line.length / v * 1.1 + 0.5
        if need * factor > 60:
            raise ShapeMoveError(f"walking {line.length:.1f} m at {v:.2f} m/s takes {need:.0f} s, over 60 s: "
                                 "use a shorter path or give --seconds")
        if progress is not None:
            progress(0.5, f"a {need:.1f} s motion for a {line.length:.1f} m path")
        req.seconds = need * factor
        motion = gen.generate_batch([req])[0]
        req.seconds = None
    warnings = list(motion.warnings)
    if speed is not None:
        motion = time_warp(motion, gen.body, speed=speed, ik_refine_iters=gen.ik_refine_iters)
    out = follow_path(motion, gen.body, line, crop=not fixed, ik_refine_iters=gen.ik_refine_iters)
    out.warnings = warnings + out.warnings
    out.shape_source = motion.shape_source
    return out


def path_report(motion: Motion, path) -> dict:
    """Root (pelvis) distance to the path (mean, max, m), facing vs the path's tangent at the
    nearest point (mean, max, degrees)."""
    line = path if isinstance(path, Polyline) else Polyline(path)
    J = np.asarray(motion.joints, np.float64)
    dist, yaw = line.nearest(J[:, 0, [0, 2]])
    face = heading_angles(facing_directions(J))
    err = np.degrees(np.abs(np.angle(np.exp(1j * (face - yaw)))))
    return {"root_mean_m": float(dist.mean()), "root_max_m": float(dist.max()),
            "facing_mean_deg": float(err.mean()), "facing_max_deg": float(err.max()),
            "travel_m": float(travel(J)[-1]), "path_m": line.length}
