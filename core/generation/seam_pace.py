"""A timeline's seams paced: the change from one segment's action to the next is no faster than
the segments themselves move.

The decoder writes the transition between two segments' codes in about one code (4 frames): "a
person walks forward" 3 s -> "a person waves with the right hand" 3 s (seed 0) raises the right
wrist 24 cm in one frame at the seam, 3.2x the 99th percentile of its steps elsewhere. The frames
around each seam are re-timed (``paced_seams``): the same poses in the same order, played so that
the seam's steps are spread evenly over a window of frames either side of it. A step's cost is its
largest joint step over that joint's 99th percentile step inside the segments (``joint_p99``,
frames away from every seam); the window grows, code by code, from ``WINDOW`` frames either side
up to ``MAX_WINDOW`` (and never past half a neighbouring segment) until its evenly spread cost is
at most ``TARGET``. Each re-timed frame is the pose at its fractional source time, linearly
between the two frames around it, so a planted foot stays planted. The window's first and last
frames are kept, so the segments keep their bounds and length, and the frames outside every
window are untouched. ``seam_steps`` reads what ``sequence.boundary_report`` reports: the worst
step within ``SEAM`` frames of a seam, over the same percentile.
"""
from __future__ import annotations

import numpy as np

SEAM = 4          # frames either side of a boundary whose steps are the seam's (one code)
WINDOW = 8        # frames either side of a seam a transition is first spread over
MAX_WINDOW = 12   # ... and at most (3 codes: Regenerate Strip keeps the frames further from a seam)
TARGET = 1.0      # the evenly spread cost (a step over its joint's p99) a window is widened to reach
LIMIT = 1.2       # a seam whose worst step costs at most this is left as it is


def steps(joints) -> np.ndarray:
    """(T-1, J) distance (m) each joint moves from frame t to t+1."""
    return np.linalg.norm(np.diff(np.asarray(joints, np.float64), axis=0), axis=-1)


def seam_mask(num_steps: int, starts, width: int = SEAM) -> np.ndarray:
    """(num_steps,) True for the steps within ``width`` frames of a segment start in ``starts``
    (step t goes from frame t to t+1)."""
    near = np.zeros(num_steps, bool)
    for s in starts:
        near[max(0, s - width):min(num_steps, s + width)] = True
    return near


def joint_p99(joints, starts, width: int = SEAM) -> np.ndarray:
    """(J,) each joint's 99th percentile step over the frames more than ``width`` from a seam."""
    st = steps(joints)
    inside = ~seam_mask(len(st), starts, width)
    return np.percentile(st[inside] if inside.sum() >= 4 else st, 99, axis=0)


def seam_steps(joints, starts) -> list[float]:
    """Per segment start in ``starts``, the worst step within ``SEAM`` frames of it over its joint's
    99th percentile step inside the segments."""
    st = steps(joints)
    p99 = np.maximum(joint_p99(joints, starts), 1e-6)
    return [float((st[max(0, s - SEAM):min(len(st), s + SEAM)] / p99).max()) for s in starts]


def source_times(cost: np.ndarray) -> np.ndarray:
    """(n+1,) the fractional source frame (0..n) each of n+1 re-timed frames shows so that each of
    the n steps has the same share of ``cost`` (n,): where the cumulative cost reaches that share."""
    cum = np.r_[0.0, np.cumsum(cost)]
    return np.interp(np.linspace(0.0, cum[-1], len(cum)), cum, np.arange(len(cum), dtype=np.float64))


def at_times(frames: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``frames`` (n+1, ...) at the fractional frames ``u``, linearly between the frames around each."""
    i = np.minimum(np.floor(u).astype(int), len(frames) - 2)
    f = (u - i).reshape(-1, *([1] * (frames.ndim - 1)))
    return (1 - f) * frames[i] + f * frames[i + 1]


def paced_seams(joints, contacts, bounds) -> tuple[np.ndarray, np.ndarray] | None:
    """(joints (T,J,3), contacts (T,4)) of a timeline with each seam's transition spread over the
    frames around it (module doc); None when no seam steps faster than ``LIMIT`` x its joints'
    99th percentile inside the segments."""
    J = np.asarray(joints, np.float64).copy()
    C = np.asarray(contacts).copy()
    b = np.asarray(bounds)
    starts = [int(s) for s in b[1:, 0]]
    if not starts or len(J) < 8:
        return None
    p99 = np.maximum(joint_p99(J, starts), 1e-6)
    changed = False
    for k, s in enumerate(starts):
        before, after = b[k, 1] - b[k, 0], b[k + 1, 1] - b[k + 1, 0]
        lo_room = before // 2 if k > 0 else before - 1      # a neighbour's window may take the other half
        hi_room = after // 2 if k + 2 < len(b) else after - 1
        cost = (steps(J) / p99).max(axis=1)
        if cost[max(0, s - SEAM):s + SEAM].max() <= LIMIT:
            continue
        w = WINDOW
        while True:
            lo, hi = s - min(w, lo_room), s + min(w, hi_room)
            spread = cost[lo:hi].mean()
            if spread <= TARGET or w >= MAX_WINDOW or (w >= lo_room and w >= hi_room):
                break
            w += SEAM
        u = source_times(cost[lo:hi])
        J[lo:hi + 1] = at_times(J[lo:hi + 1], u)
        C[lo:hi + 1] = C[lo + np.rint(u).astype(int)]
        changed = True
    return (J, C) if changed else None
