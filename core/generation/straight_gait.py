"""A captured gait on a bend, played on a straight line.

The data's jogs are HDM05's "jog in a circle to the left" (four steps from standing, turning by
50-115 degrees in 2 s) and one DeepMimic cycle: asked "a person jogs", none of them competed, since
a plain gait's take must go straight (``typical_pace.unplain_take``) and a bend does not loop (its
cycle turns more than ``take_loop.MOST_TURN``). Taken off its bend, a take is the same steps on a
line:

- **the turn**: each frame's body is turned about the vertical by the heading it has gained since
  the first frame (its facing, the hips' swing of each step smoothed away by a local straight-line
  fit, which, unlike a plain average, does not lag at the take's ends), and the root's path is
  rebuilt from its own frame-to-frame steps turned the same way, its height kept;
- **the lean**: a body going round a bend leans into it (the HDM05 jogs' necks 9-14 degrees inside
  their feet once under way); each frame's body is turned about its facing direction, through the
  root, by the lean of the neck over the feet's middle (smoothed over ``LEAN_SIGMA``), so it runs
  upright (a take on a line leans by a degree or so, and loses that too).

What stays of the bend is where the feet land across the line and, for some takes, a body facing
up to 12 degrees off it (the performer looked into the turn).

The other gaits' takes (a march, a limp, a zombie walk, a long sneak) are not straightened: CMU's
and DeepMimic's go up a room, turn round and come back (CMU 105_19, the data's one march, turns by
200 degrees at 7 s). Asked along a line ("a soldier marches forward"), such a take plays its longest
stretch whose heading stays within ``LINE_BAND`` (``line_asked``, ``line_stretch``: the march's
first 7.2 s), looped on its last stride where the length asked is longer, instead of the turn and
the way back.

Which prompts: one gait that goes on along a line (``typical_pace.lined_gait``: "jogs", "trots
along slowly", "walks forward quickly"; no course, turn, place, second thing or way other than
forward asked; ``straight_asked``); "jogs in a circle" or "jogs to the left" keeps the takes' bends.

    rotations, root = straightened(rotations, root, joints)   # (T,24,3,3), (T,3); joints (T,J,3)
"""
from __future__ import annotations

import numpy as np

from ..geometry.rotations import axis_angle_to_matrix, yaw_matrix
from ..motion.skeleton_ops import facing_directions, gaussian_smooth, heading_angles, smooth_directions
from .track import HEADING_SIGMA

STRAIGHTENED = ("walk", "jog", "run")   # the plain gaits whose takes are played off their bends
LINE_BAND = np.radians(45.0)            # another gait's take asked along a line: its stretch within this heading band
LEAN_SIGMA = 8.0                        # frames: the lean without the sway of each step
NECK, FEET = 12, (7, 8, 10, 11)         # the lean: the neck over the ankles' and toes' middle


def straight_asked(words) -> bool:
    """Whether the words (``plan.words.Words``) ask one gait going on along a line (module doc;
    ``typical_pace.lined_gait``)."""
    from .typical_pace import lined_gait

    return lined_gait(words) is not None


def line_asked(words) -> bool:
    """Whether the words (``plan.words.Words``) ask one gait of the plan's (``vocabulary.GAITS``: a
    march, a limp) going along a line: no course, turn, place or second thing, no way but forward."""
    from ..plan.vocabulary import GAITS
    from .typical_pace import along_a_line

    return words is not None and len(words.actions) == 1 and words.actions[0] in GAITS and along_a_line(words)


def straightened(rotations, root, joints) -> tuple[np.ndarray, np.ndarray]:
    """Local rotations (T,24,3,3) and root path (T,3) of a take whose posed ``joints`` (T,J,3) turn
    as they go, turned back frame by frame to its first frame's heading and stood upright (module
    doc)."""
    rotations = np.asarray(rotations, np.float64)
    root = np.asarray(root, np.float64)
    J = np.asarray(joints, np.float64)
    gained = heading_gained(J)
    back = yaw_matrix(-gained)                                        # (T,3,3)
    facing = _facing(J)
    upright = axis_angle_to_matrix(facing * lean(J, facing)[:, None])   # about the facing, through the root
    out = rotations.copy()
    out[:, 0] = back @ upright @ rotations[:, 0]
    steps = np.diff(root, axis=0)
    mid = yaw_matrix(-(gained[1:] + gained[:-1]) / 2)                 # a step turned by its middle's heading
    turned = np.einsum("tij,tj->ti", mid, steps)
    path = np.concatenate([root[:1], root[:1] + np.cumsum(turned, axis=0)])
    path[:, 1] = root[:, 1]
    return out.astype(np.float32), path.astype(np.float32)


def heading_gained(joints, sigma: float = HEADING_SIGMA) -> np.ndarray:
    """(T,) the yaw (radians) the body has turned by since frame 0: its facing (hips and shoulders
    across, unwrapped) fitted at each frame by a straight line weighted by a Gaussian of ``sigma``
    frames around it (a steady turn is followed to the last frame)."""
    raw = np.unwrap(heading_angles(facing_directions(np.asarray(joints, np.float64))))
    t = np.arange(len(raw), dtype=np.float64)
    d = t[None, :] - t[:, None]                                  # (T,T): frame k seen from frame t
    w = np.exp(-0.5 * (d / sigma) ** 2) * (np.abs(d) <= 4 * sigma)
    s0, s1, s2 = w.sum(1), (w * d).sum(1), (w * d * d).sum(1)
    y0, y1 = w @ raw, (w * d) @ raw
    fit = (s2 * y0 - s1 * y1) / np.maximum(s0 * s2 - s1 * s1, 1e-12)
    return fit - fit[0]


def line_stretch(joints, band: float = LINE_BAND) -> tuple[int, int]:
    """(lo, hi): the longest stretch of frames of posed ``joints`` (T,J,3) whose heading
    (``heading_gained``) stays within ``band`` radians, its first such stretch on a tie; (0, T) for a
    take that never turns so far."""
    h = heading_gained(joints)
    best = (0, len(h))
    if len(h) == 0 or h.max() - h.min() <= band:
        return best
    size = 0
    for lo in range(len(h)):
        if len(h) - lo <= size:
            break
        spread = np.maximum.accumulate(h[lo:]) - np.minimum.accumulate(h[lo:])
        over = np.flatnonzero(spread > band)
        hi = lo + (int(over[0]) if len(over) else len(h) - lo)
        if hi - lo > size:
            size, best = hi - lo, (lo, hi)
    return best


def lean(joints, facing=None) -> np.ndarray:
    """(T,) radians the neck leans over the feet's middle to the body's left (right-handed about its
    facing direction: + leans left), smoothed over ``LEAN_SIGMA`` frames."""
    J = np.asarray(joints, np.float64)
    facing = _facing(J) if facing is None else facing
    left = np.cross([0.0, 1.0, 0.0], facing)
    up = J[:, NECK] - J[:, list(FEET)].mean(1)
    side = gaussian_smooth(np.einsum("ti,ti->t", up, left), LEAN_SIGMA)
    height = gaussian_smooth(up[:, 1], LEAN_SIGMA)
    return np.arctan2(side, np.maximum(height, 1e-6))


def _facing(J) -> np.ndarray:
    """(T,3) unit horizontal facing directions, the step's hip swing smoothed away."""
    return smooth_directions(facing_directions(J), HEADING_SIGMA)
