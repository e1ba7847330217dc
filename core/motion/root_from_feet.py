"""The root's horizontal travel derived from what the legs do: planted feet do not move.

Issue #24's fallback: if a decoded motion's legs stepped further than its root travels (planted
feet skating backward), the feet would give the travel back. This module re-derives the root's
horizontal path from the feet alone (measured in docs/codec.md: on the shipped SA-VAE the decoded
feet agree with the decoded root, so it gives the same short travel; the codec must carry it):

- between frames t and t+1, every contact joint (heels = ankles 7, 8, toes = ball joints 10, 11,
  ``motion.contacts.CONTACT_IDS``) in contact at both frames is taken to stay fixed in the world,
  so the root moves by minus the change of that joint's horizontal offset from the root
  (``foot - root``, in world axes: the body's own turning is kept); several planted joints are
  averaged, the joints lowest above the floor weighted most (``planted_steps``);
- steps with no planted joint (a run's flight, a missed contact) keep the motion's own root step
  (``flight="keep"``, the default: on real runs the travel then comes out 1.00x, against 0.97x)
  or take a velocity interpolated between the nearest planted steps (``flight="interpolate"``);
- the root's height and every joint's offset from the root are unchanged: the whole frame moves
  horizontally, so the pose, the turning and the vertical motion are the decoder's.

    out = root_from_feet(joints, contacts)      # (T,22,3) with the feet's travel
    path = feet_root_path(joints, contacts)     # (T,2) the root's x, z (starts where it started)
"""
from __future__ import annotations

import numpy as np

from ..errors import ShapeMoveError
from .contacts import CONTACT_IDS, floor_levels

HEIGHT_SCALE = 0.01   # m: a planted joint this far above its floor level counts 1/e as much


def _check(joints, contacts) -> tuple[np.ndarray, np.ndarray]:
    j = np.asarray(joints, dtype=np.float64)
    if j.ndim != 3 or j.shape[1] < 22 or j.shape[2] != 3 or len(j) < 2:
        raise ShapeMoveError(f"root_from_feet needs (frames >= 2, 22, 3) joints, got shape {j.shape}")
    if not np.isfinite(j).all():
        raise ShapeMoveError("root_from_feet: the joints hold NaN or infinite values")
    c = np.asarray(contacts)
    if c.shape != (len(j), 4):
        raise ShapeMoveError(f"root_from_feet needs ({len(j)}, 4) contacts of joints 7, 8, 10, 11 "
                             f"(one row per frame), got shape {c.shape}")
    return j, c.astype(bool)


def planted_steps(joints, contacts, height_scale: float = HEIGHT_SCALE) -> tuple[np.ndarray, np.ndarray]:
    """(T,22,3) joints, (T,4) contacts -> ((T-1,2) root x, z step from frame t to t+1 implied by the
    joints planted at both frames (NaN where none is), (T-1,) bool: which steps had one).

    Each planted joint's implied step is weighted by exp(-h / ``height_scale``), h its height (the
    higher of the two frames) above its joint type's floor level (``contacts.floor_levels``): a
    heel rising in a toe-off or a toe coming down at a heel strike is rolling, not planted, so it
    counts less than the joint flat on the floor (on real walks the root's travel comes out 0.99x
    its own with the weights, 0.98x with a plain mean). ``height_scale`` 0: a plain mean."""
    j, c = _check(joints, contacts)
    if not height_scale >= 0:
        raise ShapeMoveError(f"height_scale must be >= 0 (metres), got {height_scale}")
    rel = j[:, CONTACT_IDS][..., [0, 2]] - j[:, None, 0, [0, 2]]     # (T,4,2) foot joints from the root
    implied = -(rel[1:] - rel[:-1])                                  # root step that keeps each still
    both = c[1:] & c[:-1]                                            # (T-1,4) planted across the step
    if height_scale > 0:
        h = j[:, CONTACT_IDS, 1] - np.repeat(floor_levels(j), 2)[None]
        w = np.exp(-np.clip(np.maximum(h[1:], h[:-1]), 0.0, None) / height_scale)
    else:
        w = np.ones(both.shape)
    w = np.where(both, w, 0.0)
    total = w.sum(-1)
    known = total > 0
    step = (implied * w[..., None]).sum(1) / np.where(known, total, 1.0)[:, None]
    step[~known] = np.nan
    return step, known


def fill_steps(step: np.ndarray, known: np.ndarray) -> np.ndarray:
    """(N,2) steps with NaN where ``known`` is False -> every step known: linear interpolation
    between the nearest known steps, the first/last known one held at the ends."""
    if not known.any():
        raise ShapeMoveError("root_from_feet: no foot is planted in two consecutive frames, so the feet "
                             "say nothing about the root's travel (is this motion airborne, or are the "
                             "contacts empty?)")
    t = np.arange(len(step))
    return np.stack([np.interp(t, t[known], step[known, d]) for d in range(2)], axis=-1)


FLIGHT = ("keep", "interpolate")


def feet_root_path(joints, contacts, height_scale: float = HEIGHT_SCALE, flight: str = "keep") -> np.ndarray:
    """(T,22,3) joints, (T,4) contacts -> (T,2) the root's horizontal path (x, z) from the planted
    feet, starting at the clip's own first root position. ``flight``: what the steps without a
    planted joint do, "keep" the joints' own root step or "interpolate" (``fill_steps``)."""
    if flight not in FLIGHT:
        raise ShapeMoveError(f"flight must be one of {', '.join(FLIGHT)}, got {flight!r}")
    j, _ = _check(joints, contacts)
    step, known = planted_steps(j, contacts, height_scale)
    steps = fill_steps(step, known)
    if flight == "keep":
        steps[~known] = np.diff(j[:, 0, [0, 2]], axis=0)[~known]
    return j[0, 0, [0, 2]] + np.concatenate([np.zeros((1, 2)), np.cumsum(steps, axis=0)])


def root_from_feet(joints, contacts, height_scale: float = HEIGHT_SCALE, flight: str = "keep") -> np.ndarray:
    """(T,22,3) joints (metres, Y up, e.g. ``joints_from_features`` of decoded features) and (T,4)
    contacts of joints 7, 8, 10, 11 (the decoder's channels, ``body.plant.contacts_from_features``,
    or ``motion.contacts.detect_contacts``) -> (T,22,3) float64 joints, each frame moved
    horizontally so the root follows ``feet_root_path`` (``flight``: see there): planted feet stay
    where they are."""
    j, _ = _check(joints, contacts)
    path = feet_root_path(j, contacts, height_scale, flight)
    out = j.copy()
    out[..., [0, 2]] += (path - j[:, 0, [0, 2]])[:, None]
    return out
