"""Planted feet: contact-aware IK targets and grounding on the mesh soles.

Mocap retargeted by IK onto another body keeps a few cm of joint error, so feet that stood still
in the capture slide and hover on the body, and a body grounded by its lowest foot *joint* sinks
(the soles are below the joints). Two steps fix that:

1. ``plant_targets``: before IK, move the targets of the joints in contact (heels = ankles,
   toes = ball joints, ``core.motion.contacts``) onto one fixed point per contact run: its XZ is
   the run's mean, its height the joint's sole offset on the body (``soles.sole_offsets``), so
   the sole touches y = 0. The source floor is estimated from the contacts themselves. The
   change fades out over ``FADE`` frames around each run so the targets stay continuous. IK
   (``ik.solve_ik``, which weights the ankles and feet most) then lands the feet there.
2. ``ground_shift``: after posing, a per-frame vertical shift of the whole body computed on the
   mesh (``soles.GroundProbe``): on frames with a contact, the lowest vertex of the foot in
   contact goes to y = 0; between contact frames the shift is interpolated (a jump keeps its
   flight); no frame leaves any probe point under the floor.
"""
from __future__ import annotations

import numpy as np

from ..motion.contacts import CONTACT_IDS, runs

FADE = 4          # frames over which a planted target blends back into the mocap target


def source_floor(joints, contacts, sole_offsets) -> float:
    """Height of the floor in the source's coordinates: the median over contact events of the
    contact joint's height minus its sole offset (without contacts: the lowest such value)."""
    j = np.asarray(joints, dtype=np.float64)[:, CONTACT_IDS, 1] - np.asarray(sole_offsets)[None]
    c = np.asarray(contacts).astype(bool)
    return float(np.median(j[c])) if c.any() else float(j.min())


def plant_targets(joints, contacts, sole_offsets, fade: int = FADE) -> tuple[np.ndarray, float]:
    """joints (T,22,3) mocap targets, contacts (T,4) of joints 7, 8, 10, 11, sole_offsets (4,) of
    the body the IK will fit -> (targets (T,22,3) with the floor at y = 0 and planted contact
    joints, source floor height that was subtracted)."""
    tgt = np.array(joints, dtype=np.float64)
    T = len(tgt)
    floor = source_floor(tgt, contacts, sole_offsets)
    tgt[..., 1] -= floor
    for k, j in enumerate(CONTACT_IDS):
        corr = np.zeros((T, 3))
        weight = np.zeros(T)
        for s, e in runs(np.asarray(contacts)[:, k]):
            anchor = np.r_[tgt[s:e, j, 0].mean(), sole_offsets[k], tgt[s:e, j, 2].mean()]
            corr[s:e] = anchor[None] - tgt[s:e, j]
            weight[s:e] = 1.0
            for d in range(1, fade + 1):  # fade the change of the run's edges out over `fade` frames
                w = 1.0 - d / (fade + 1)
                for t, edge in ((s - d, s), (e - 1 + d, e - 1)):
                    if 0 <= t < T and weight[t] < w:
                        corr[t], weight[t] = (anchor - tgt[edge, j]) * w, w
        tgt[:, j] += corr
    return tgt, floor


def ground_shift(per_foot, lowest_all, contacts) -> np.ndarray:
    """(T,) vertical shift that grounds a posed body on its mesh.

    per_foot (T,2) lowest vertex of the left/right foot, lowest_all (T,) lowest point of the body,
    contacts (T,4) of joints 7, 8, 10, 11. Frames where a foot is in contact: that foot's lowest
    vertex (the lower of two) goes to 0. Other frames: the shift is interpolated between contact
    frames (held at the ends). No contact at all: one shift for the clip, lowest point on 0.
    Finally every frame is lifted where needed so that no point is below the floor."""
    c = np.asarray(contacts).astype(bool)
    foot_on = np.stack([c[:, 0] | c[:, 2], c[:, 1] | c[:, 3]], axis=1)        # left, right
    support = foot_on.any(1)
    low_all = np.asarray(lowest_all, dtype=np.float64)
    if support.any():
        lowest_contact = np.where(foot_on, np.asarray(per_foot, dtype=np.float64), np.inf).min(1)
        t = np.arange(len(c))
        shift = np.interp(t, t[support], -lowest_contact[support])
    else:
        shift = np.full(len(c), -low_all.min())
    return np.maximum(shift, -low_all)
