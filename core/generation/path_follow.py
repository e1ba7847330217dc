"""Along a path: a locomotion motion walks a polyline at its own speed, turning where it turns.

``follow_path(motion, body, path)``: the decoder's joint track is split into the root's smoothed
course (``track.root_centre``; its distance travelled s(t)) and heading (``track.headings``), and
the body relative to both (sway, hip swing and limbs kept). The body is then put down at the
path's point at the same distance s(t), turned to the path's tangent there; the contacts are
planted again (``track.plant``), so a stance foot stays on one point while the path turns under
the body. Without ``seconds`` the clip ends where the path ends (the motion must travel at least
that far: ``generate_along_path`` asks the model for a long enough motion); with it, the motion
keeps its length and goes on along the last tangent if it is longer than the path.

Paths: a JSON list of [x, z] points in metres (Y up, as the motion file), read into a
``polyline.Polyline`` (resampled, corners rounded) and walked with ``polyline.follow_track``.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from ..motion.skeleton_ops import facing_directions, heading_angles
from ..scene.motion_file import Motion
from .polyline import MIN_SPEED, Polyline, check_path, follow_track
from .track import motion_speed, plant, track_of, travel


END_SLACK = 0.25   # m short of a path's end that a motion may stop without a warning


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


def follow_path(motion: Motion, body, path, crop: bool = True, ik_refine_iters: int = 10) -> Motion:
    """``motion`` walked along ``path`` ((N,2) [x, z] points or a ``Polyline``), feet re-planted."""
    line = path if isinstance(path, Polyline) else Polyline(path)
    track = track_of(motion)
    v = motion_speed(track.joints, motion.fps)
    if v < MIN_SPEED:
        raise ShapeMoveError(f"this motion travels {v:.2f} m/s: following a path needs a motion that moves "
                             "forward, e.g. 'a person walks forward'")
    out = plant(body, motion.betas, follow_track(track, line, crop), ik_refine_iters, prompt=motion.prompt)
    # how far along the path the body ends: the distance its own course travelled (follow_track puts
    # it down there), not the length of the planted root's path, which cuts the rounded corners
    short = line.length - float(travel(track.joints)[-1])
    if crop and short > END_SLACK:
        out.warnings = [f"the motion ends {short:.2f} m before the path's end"]
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
