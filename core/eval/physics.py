"""Ground-contact plausibility: penetrate, float and foot skating (metres in, cm / % out).

Conventions: Y up, ground plane y = 0, 20 fps. All functions are vectorised over frames.

Definitions (as in HUMOS's ``all_physics_metrics``, which implements the PhysDiff wording
"distance below/above the ground of the lowest body-mesh vertex"):

* **penetrate**: per frame, ``h = min_v y_v`` (lowest vertex). A frame *penetrates* when
  ``h < -tol``; the metric is the mean of ``-h`` over those frames only (cm). ``tol`` (5 mm)
  absorbs mesh approximations. PhysDiff/UHC average over *all* frames (0 where there is no
  penetration): that is ``value * n_penetrate / n_frames`` from the counts ``evaluate`` returns.
* **float**: a frame *floats* (is unsupported) when ``h > tol``; the metric is the mean of ``h``
  over those frames (cm). A motion that jumps floats during the flight phase, as in HUMOS/PhysDiff.
* **skate** (GMD's "foot skating ratio", Karunratanakul et al. 2023): over the T-1 pairs of
  adjacent frames, the % of pairs in which a foot *in contact in both frames* moves horizontally
  (XZ) by more than ``max_step`` and whose mean XZ step over a centred ``window`` of pairs also
  exceeds it (GMD: height 5 cm, 0.5 m/s = 2.5 cm per frame at 20 fps, 5-frame window; these are
  the defaults). With a mesh, a foot is the set of vertices whose dominant skin weight is its ankle
  or foot joint; it is in contact when some of its vertices are below ``height`` in both frames,
  and its step is the mean XZ displacement of exactly those vertices (the part that should stay
  planted). Without a mesh, the foot is the foot joint (10/11) as in GMD. GMD pads the window with
  zeros (clip edges never skate); we repeat the edge values instead. ``STRICT_SKATE`` (2.5 mm per
  frame, no window) flags any slide over 5 cm/s, e.g. a planted foot sliding 1 cm per frame, but
  on real mocap it also flags most swing-phase frames where the foot passes low over the ground
  (CMU walking 02_01, foot joints: 91 % strict vs 21 % GMD), so it is not the default.

The paper's tables (ShapeMove, HUMOS, PhysDiff) average penetrate and float over ALL frames (0 on a
frame without it), no tolerance: ``penetrate_all`` / ``floating_all``; ``evaluate_motion`` reports
both definitions (``penetrate_cm``/``float_cm`` and ``penetrate_all_cm``/``float_all_cm``).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import torch

from ..body.skeleton import FOOT_JOINTS as FOOT_JOINT_IDS  # 7, 8, 10, 11 (FOOT_JOINTS here: by side)
from ..errors import ShapeMoveError

GROUND_TOL = 0.005          # m, penetrate / float tolerance (HUMOS)
CONTACT_HEIGHT = 0.05       # m, foot contact height (GMD, HUMOS)
SKATE_STEP = 0.025          # m per frame at 20 fps (0.5 m/s, GMD)
SKATE_WINDOW = 5            # frames (GMD)
GMD_SKATE = {"height": CONTACT_HEIGHT, "max_step": SKATE_STEP, "window": SKATE_WINDOW}
STRICT_SKATE = {"height": CONTACT_HEIGHT, "max_step": 0.0025, "window": 1}
FOOT_JOINTS = {"left": (7, 10), "right": (8, 11)}   # ankle, foot (SMPL order)


class Stat(NamedTuple):
    """A metric value and the number of frames (or frame pairs) it is averaged over."""
    value: float
    count: int


def _np(x, name: str, ndim: int) -> np.ndarray:
    a = x.detach().cpu().numpy() if isinstance(x, torch.Tensor) else np.asarray(x)
    if a.ndim != ndim or a.shape[-1] != 3:
        raise ShapeMoveError(f"{name} must have {ndim} dimensions ending in 3 (x,y,z), got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ShapeMoveError(f"{name} contains NaN or infinite values")
    return a.astype(np.float64)


def lowest_heights(vertices) -> np.ndarray:
    """(T,V,3) vertices (or (T,J,3) joints) -> (T,) height of the lowest point per frame, m."""
    return _np(vertices, "vertices", 3)[..., 1].min(axis=1)


def lowest_from_joints(joints, sole_offsets=None) -> np.ndarray:
    """Joint-only fallback for the lowest point: (T,>=22,3) joints -> (T,) estimated sole height.

    Uses the ankle and foot joints (7, 8, 10, 11) minus their rest height above the sole
    (``sole_offsets`` (4,), from ``sole_offsets(body, betas)``; 0 = raw joint heights as GMD).
    """
    j = _np(joints, "joints", 3)
    if j.shape[1] < 22:
        raise ShapeMoveError(f"joints must have at least 22 joints (SMPL order), got {j.shape[1]}")
    off = np.zeros(4) if sole_offsets is None else np.asarray(sole_offsets, dtype=np.float64)
    return (j[:, FOOT_JOINT_IDS, 1] - off).min(axis=1)


def sole_offsets(body, betas=None) -> np.ndarray:
    """(4,) rest-pose height of joints 7, 8, 10, 11 above the lowest vertex of the body."""
    with torch.no_grad():
        joints = body.rest_joints(betas)[0].double().numpy()
        verts = body.rest_vertices(betas)[0].double().numpy()
    return joints[FOOT_JOINT_IDS, 1] - verts[:, 1].min()


def penetrate(lowest, tol: float = GROUND_TOL) -> Stat:
    """Mean depth (cm) below the ground of the lowest point, over frames with ``lowest < -tol``."""
    h = np.asarray(lowest, dtype=np.float64)
    hit = h < -tol
    return Stat(float(-h[hit].mean() * 100) if hit.any() else 0.0, int(hit.sum()))


def floating(lowest, tol: float = GROUND_TOL) -> Stat:
    """Mean height (cm) above the ground of the lowest point, over frames with ``lowest > tol``."""
    h = np.asarray(lowest, dtype=np.float64)
    hit = h > tol
    return Stat(float(h[hit].mean() * 100) if hit.any() else 0.0, int(hit.sum()))


def penetrate_all(lowest) -> Stat:
    """The paper's penetrate (PhysDiff/HUMOS tables): mean over ALL frames of the lowest point's
    depth below y = 0 (cm; 0 on frames above it), no tolerance."""
    h = np.asarray(lowest, dtype=np.float64)
    return Stat(float(np.maximum(-h, 0).mean() * 100) if h.size else 0.0, int(h.size))


def floating_all(lowest) -> Stat:
    """The paper's float: mean over ALL frames of the lowest point's height above y = 0 (cm; 0 on
    frames below it), no tolerance."""
    h = np.asarray(lowest, dtype=np.float64)
    return Stat(float(np.maximum(h, 0).mean() * 100) if h.size else 0.0, int(h.size))


def _window_mean(x: np.ndarray, window: int) -> np.ndarray:
    """(N,) -> centred moving average over ``window`` samples, edge values repeated."""
    if window <= 1 or len(x) == 0:
        return x
    left = (window - 1) // 2
    padded = np.pad(x, (left, window - 1 - left), mode="edge")
    return np.convolve(padded, np.ones(window) / window, mode="valid")


def skate(feet: list, height: float = CONTACT_HEIGHT, max_step: float = SKATE_STEP,
          window: int = SKATE_WINDOW) -> Stat:
    """Foot skating ratio (%) over the T-1 adjacent frame pairs.

    ``feet``: one (T,P,3) array per foot (its vertices, or (T,1,3) for a joint). A foot is in
    contact over a pair when any of its points is below ``height`` in both frames; its step is
    the mean XZ displacement of those points. A pair skates when some foot in contact steps more
    than ``max_step`` and the foot's mean step (all its points) over ``window`` pairs does too.
    Returns (% of pairs that skate, number of pairs).
    """
    skating = None
    for pts in feet:
        p = _np(pts, "foot points", 3)
        if p.shape[0] < 2:
            return Stat(0.0, 0)
        low = p[..., 1] < height
        both = low[:-1] & low[1:]                                   # (T-1,P)
        d = np.linalg.norm(p[1:, :, [0, 2]] - p[:-1, :, [0, 2]], axis=-1)
        n = both.sum(-1)
        contact = n > 0
        step = np.where(contact, (d * both).sum(-1) / np.maximum(n, 1), 0.0)
        s = contact & (step > max_step) & (_window_mean(d.mean(-1), window) > max_step)
        skating = s if skating is None else skating | s
    if skating is None:
        raise ShapeMoveError("skate needs at least one foot")
    return Stat(float(skating.mean() * 100), int(skating.size))


def foot_vertex_ids(skin_weights) -> dict[str, np.ndarray]:
    """Vertex indices of each foot: dominant skin weight on its ankle or foot joint."""
    w = skin_weights.detach().cpu().numpy() if isinstance(skin_weights, torch.Tensor) else np.asarray(skin_weights)
    label = w.argmax(axis=1)
    out = {side: np.flatnonzero(np.isin(label, joints)) for side, joints in FOOT_JOINTS.items()}
    for side, ids in out.items():
        if ids.size == 0:
            raise ShapeMoveError(f"the body model has no vertices skinned to the {side} ankle/foot")
    return out


STANCE_SLIDE_STEP = 0.0025   # m per frame (5 cm/s): a planted joint moving more than this slides


def stance_slide(joints, contacts, max_step: float = STANCE_SLIDE_STEP) -> tuple[Stat, Stat]:
    """Slide of the feet that are KNOWN to be planted (not a paper metric; ``skate`` decides contact
    from the height under a 5 cm line, so a body that floats above it never skates).

    joints (T,>=22,3), contacts (T,4) of joints 7, 8, 10, 11 (heels, balls; ``motion.contacts``,
    e.g. the source capture's). Over the frame pairs in which a joint is in contact in both frames:
    (mean XZ step of that joint in mm, number of joint-pairs) and (% of those joint-pairs that step
    more than ``max_step``, number of joint-pairs). No contact at all: (0, 0) twice."""
    j = _np(joints, "joints", 3)
    c = np.asarray(contacts).astype(bool)
    if j.shape[1] < 22 or c.ndim != 2 or c.shape[1] != 4 or len(c) != len(j):
        raise ShapeMoveError(f"stance_slide needs (T,>=22,3) joints and (T,4) contacts, got {j.shape} and {c.shape}")
    both = c[:-1] & c[1:]                                                   # (T-1,4)
    step = np.linalg.norm(np.diff(j[:, FOOT_JOINT_IDS][..., [0, 2]], axis=0), axis=-1)
    n = int(both.sum())
    if n == 0:
        return Stat(0.0, 0), Stat(0.0, 0)
    return Stat(float(step[both].mean() * 1000), n), Stat(float((step[both] > max_step).mean() * 100), n)


def skate_from_joints(joints, height: float = CONTACT_HEIGHT, max_step: float = SKATE_STEP,
                      window: int = SKATE_WINDOW) -> Stat:
    """Joint-only fallback (GMD): the feet are the foot joints 10 and 11 of (T,>=22,3) joints."""
    j = _np(joints, "joints", 3)
    if j.shape[1] < 22:
        raise ShapeMoveError(f"joints must have at least 22 joints (SMPL order), got {j.shape[1]}")
    return skate([j[:, [FOOT_JOINTS["left"][1]]], j[:, [FOOT_JOINTS["right"][1]]]], height, max_step, window)
