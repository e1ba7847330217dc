"""Strides scaled: a gait's travel and the reach of its feet made ``scale`` times theirs, its
cadence, heights and upper body kept.

Used where the words ask a gait to go less far than the model's motion does: in place
(``on_the_spot.py``, a scale near 0) and a slow jog or run (``slow_steps.py``, where playing it
slower would hang its flights in the air).

- the root's horizontal path and each ankle's (and foot's) offset from the root, along the body's
  heading and square to it about its mean (the stance width), are scaled by the same factor, so a
  planted foot stays planted (its place is the root's travel plus its offset, both scaled);
  heights and the upper body (carried by the root) are kept;
- each knee is placed again for its hip and its moved ankle with the leg's own bone lengths, bent
  forward (two-bone IK in the plane of the leg and the heading), so a lifted foot still lifts the
  knee instead of stretching the leg.

The caller plants the feet again (``track.replanted``).
"""
from __future__ import annotations

import numpy as np

PELVIS = 0
LEGS_CHAINS = ((1, 4, 7, 10), (2, 5, 8, 11))   # hip, knee, ankle, foot: left, right


def _knee(hip: np.ndarray, ankle: np.ndarray, thigh: np.ndarray, shin: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """(T,3) knee for (T,3) hips and ankles and (T,) bone lengths, bent toward ``forward`` (T,3)."""
    d_vec = ankle - hip
    d = np.maximum(np.linalg.norm(d_vec, axis=1), 1e-6)
    u = d_vec / d[:, None]
    reach = np.minimum(d, thigh + shin - 1e-6)
    along = (thigh ** 2 - shin ** 2 + reach ** 2) / (2 * reach)
    side = np.sqrt(np.maximum(thigh ** 2 - along ** 2, 0.0))
    bend = forward - (forward * u).sum(1, keepdims=True) * u          # forward, square to the leg
    bend /= np.maximum(np.linalg.norm(bend, axis=1, keepdims=True), 1e-6)
    return hip + along[:, None] * u + side[:, None] * bend


def scaled_strides(joints: np.ndarray, scale) -> np.ndarray:
    """(T,22,3) joints whose root path and ankle offsets (along the heading; square to it, about the
    stance width) are ``scale`` times theirs (module doc): one factor, or one per frame (a timeline's
    segments, eased in and out; the root's steps are scaled frame by frame). The knees are placed
    again where the scale is under 1; a scale of 1 everywhere gives the joints back."""
    from .track import headings

    J = np.asarray(joints, np.float64)
    s = np.minimum(np.broadcast_to(np.asarray(scale, np.float64), (len(J),)), 1.0)
    if (s >= 1.0).all():
        return J.copy()
    h = headings(J)
    fwd = np.stack([np.sin(h), np.zeros_like(h), np.cos(h)], axis=1)      # (T,3) the heading, level
    left = np.stack([np.cos(h), np.zeros_like(h), -np.sin(h)], axis=1)     # (T,3) square to it, level
    root = J[:, PELVIS] * [1.0, 0.0, 1.0]
    steps = s[1:, None] * np.diff(root, axis=0)
    moved = root[0] + np.concatenate([np.zeros((1, 3)), np.cumsum(steps, axis=0)])   # the root's path, scaled
    out = J + (moved - root)[:, None]                                       # the body carried by it
    shrink = (1.0 - s)[:, None]
    for hip, knee, ankle, foot in LEGS_CHAINS:
        thigh = np.linalg.norm(J[:, knee] - J[:, hip], axis=1)
        shin = np.linalg.norm(J[:, ankle] - J[:, knee], axis=1)
        ahead = ((J[:, ankle] - root) * fwd).sum(1)                         # the ankle's offset along the heading
        aside = ((J[:, ankle] - root) * left).sum(1)                        # ... and square to it
        new_ankle = (out[:, ankle] - shrink * ahead[:, None] * fwd
                     - shrink * (aside - aside.mean())[:, None] * left)     # its stance width kept
        out[:, foot] += new_ankle - out[:, ankle]                           # the foot keeps its direction
        out[:, ankle] = new_ankle
        out[:, knee] = np.where((s < 1.0)[:, None], _knee(out[:, hip], new_ankle, thigh, shin, fwd), out[:, knee])
    return out
