"""A captured take shorter than asked, played on as a loop where the take itself repeats.

A take of jumping jacks, arm circles or a dribble that lasts 3 s, asked for 10 s, is not held on
its last pose for 7 s: its own cycle plays again. The cycle is ``loop_cut.best_cut``'s (the two frames
a < b whose pose relative to the root and whose velocities are most alike), with two conditions
that say the take repeats rather than merely starts and ends alike:

- the cycle is cut in the take's busy stretch (its standing start and end left out: frames whose
  largest joint step is under ``STILL`` of the take's 90th percentile), lasts ``SHORTEST_CYCLE`` s
  or more and at most ``MOST_OF_TAKE`` of that stretch, so at least two cycles were performed (a
  single front kick, standing before and after, is held), and moves on average at least ``BUSY``
  x as much a frame as the stretch does; and the cycle before or after it is the same movement
  again (poses within ``REPEAT`` x the cycle's own spread);
- the seam, frame b - 1 followed by frame a moved by the cycle's advance, steps no joint farther
  than ``SEAM_STEP`` x the 99th percentile of the take's own largest joint step per frame, and the
  heading turns by at most ``MOST_TURN`` degrees over a cycle (the cycles repeat on a straight line).

The take plays from its first frame to b - 1, then a..b - 1 again and again, each repeat moved by
the cycle's advance on the floor; the contacts repeat with the frames, so planting the whole
window (``retarget.planted_retarget``) plants the repeats as the take's own steps.
"""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError

SHORTEST_CYCLE = 0.5   # s
MOST_OF_TAKE = 0.45    # the longest cycle, as a share of the take
SEAM_STEP = 1.5        # the seam's step against the 99th percentile of the take's steps
MOST_TURN = 20.0       # degrees of heading per cycle
STILL = 0.25           # a frame whose largest step is under this x the 90th percentile stands
BUSY = 0.5             # the cycle's mean step against the busy stretch's
REPEAT = 0.5           # a neighbouring cycle's pose difference against the cycle's own spread


def looped_take(rotations, root, contacts, joints, frames: int):
    """(rotations, root, contacts, first) of a take (T,24,3,3), (T,3), (T,4) whose posed ``joints``
    (T,J,3) repeat, played on to ``frames`` (> T) frames: ``first`` frames of the take as performed,
    then its cycle repeated; None when the take does not repeat (module doc) or is long enough."""
    from .loop_cut import best_cut
    from .track import headings

    n = len(rotations)
    if n >= frames:
        return None
    J = np.asarray(joints, np.float64)
    steps = np.linalg.norm(np.diff(J, axis=0), axis=-1).max(-1)            # (T-1,) largest joint step
    moving = np.flatnonzero(steps >= STILL * np.percentile(steps, 90))
    if len(moving) < 2:
        return None
    s, e = int(moving[0]), int(moving[-1]) + 2                              # the busy stretch s..e-1
    try:
        cut = best_cut(J[s:e], FPS, (SHORTEST_CYCLE, MOST_OF_TAKE * (e - s) / FPS))
    except ShapeMoveError:   # too short for two cycles of the shortest length
        return None
    a, b = cut.start + s, cut.end + s
    if steps[a:b].mean() < BUSY * steps[s:e - 1].mean() or not _repeated(J, a, b):
        return None
    h = headings(J)
    if abs(np.degrees(np.angle(np.exp(1j * (h[b] - h[a]))))) > MOST_TURN:
        return None
    root = np.asarray(root, np.float32)
    advance = (root[b] - root[a]) * np.array([1.0, 0.0, 1.0], np.float32)
    seam = np.linalg.norm(J[a] + advance - J[b - 1], axis=-1).max()
    if seam > SEAM_STEP * np.percentile(steps, 99):
        return None
    period = b - a
    reps = -(-(frames - b) // period)
    idx = np.concatenate([np.arange(b)] + [np.arange(a, b)] * reps)[:frames]
    k = np.concatenate([np.zeros(b)] + [np.full(period, i + 1.0) for i in range(reps)])[:frames]
    return (np.asarray(rotations)[idx], (root[idx] + k[:, None] * advance).astype(np.float32),
            np.asarray(contacts)[idx], b)


def _repeated(J, a: int, b: int) -> bool:
    """Whether the cycle a..b-1 was performed twice: the poses (relative to the root) of the cycle
    before it or after it differ from its own by at most ``REPEAT`` x how far its poses spread."""
    P = b - a
    rel = J - J[:, :1]
    cycle = rel[a:b]
    spread = np.linalg.norm(cycle - cycle.mean(0), axis=-1).mean()
    others = [rel[c:c + P] for c in (a - P, b) if c >= 0 and c + P <= len(J)]
    return any(np.linalg.norm(o - cycle, axis=-1).mean() <= REPEAT * spread for o in others)
