"""Slower, faster or stretched to a duration, with the feet planted again.

``time_warp(motion, body, speed=0.5)`` plays the motion at half speed (twice the frames),
``seconds=6`` stretches or squeezes it to exactly 6 s (120 frames at 20 fps). The decoder's joint
track is resampled (linear in time; contacts from the nearest source frame), then planted again
(``track.plant``), so a stance foot that the resampling moves by a fraction of a millimetre is
held on one point. A looping motion is resampled around its cycle (frame T is frame 0 moved by
``loop_advance``) and stays a loop (``loop.plant_loop``).
"""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from ..scene.motion_file import Motion
from .track import plant, resample, track_of

MIN_SPEED, MAX_SPEED = 0.5, 2.0
MIN_SECONDS, MAX_SECONDS = 0.4, 120.0


def _number_in(value, what: str, lo: float, hi: float, kind: str = "a number", unit: str = "") -> float:
    """``value`` as a float within [lo, hi]; otherwise a ShapeMoveError naming ``what``."""
    try:
        s = float(value)
    except (TypeError, ValueError):
        raise ShapeMoveError(f"{what} must be {kind}, got {value!r}") from None
    if not lo <= s <= hi:
        raise ShapeMoveError(f"{what} must be between {lo} and {hi}{unit}, got {value}")
    return s


def check_speed(speed) -> float:
    return _number_in(speed, "--speed", MIN_SPEED, MAX_SPEED)


def check_seconds(seconds, what: str = "--stretch") -> float:
    return _number_in(seconds, what, MIN_SECONDS, MAX_SECONDS, "a number of seconds", " s")


def warped_length(num_frames: int, speed: float | None = None, seconds: float | None = None,
                  fps: float = FPS) -> int:
    """Frames after the warp: ``num_frames / speed`` or ``seconds * fps`` (rounded)."""
    if (speed is None) == (seconds is None):
        raise ShapeMoveError("give either a speed or a duration to time-warp to, not both")
    n = num_frames / check_speed(speed) if speed is not None else check_seconds(seconds) * fps
    return max(2, int(round(n)))


def time_warp(motion: Motion, body, speed: float | None = None, seconds: float | None = None,
              ik_refine_iters: int = 10) -> Motion:
    """``motion`` played at ``speed`` (0.5..2) or stretched to ``seconds``; feet planted again."""
    n = warped_length(motion.num_frames, speed, seconds, motion.fps)
    track = track_of(motion)
    if motion.loop_advance is not None:
        from .loop import plant_loop

        warped = resample(track, n, motion.loop_advance)
        return plant_loop(body, motion.betas, warped, motion.loop_advance, ik_refine_iters, prompt=motion.prompt)
    out = plant(body, motion.betas, resample(track, n), ik_refine_iters, prompt=motion.prompt)
    if motion.segment_bounds is not None:  # a timeline keeps its segments, re-timed with it
        from .sequence import scaled_bounds

        out.segment_bounds = scaled_bounds(motion.segment_bounds, n)
        out.segment_prompts = list(motion.segment_prompts)
    return out
