"""Betas from body measurements or a shape text: the inverse of ``measure``.

``betas_for_measurements(body, {"height_cm": 190, "waist_cm": 100})`` finds betas whose
``measure(body, betas)`` matches the stated numbers, by Levenberg-Marquardt on

    sum_k (m_k(b) - target_k)^2  +  REG |b|^2          (m in cm, b ~ N(0,1))

``measure`` slices the mesh and is not differentiable, so the Jacobian is taken by finite
differences (once at the start, then updated by Broyden's rank-one rule, so a step costs one
measurement). Height and arm/leg lengths only need the rest vertices and joints and are computed
directly here (milliseconds, batched; ``fast_measure`` checks against ``measure`` in the tests);
girths go through ``measure_mesh`` (~0.1-0.4 s each). The prior keeps the directions the targets
don't constrain near 0, so "190 cm tall" changes height without inventing a belly.

``targets_from_shape_text`` reads a numeric shape sentence ("A person standing 190 cm tall, with
a waist circumference of 100 cm ...", ``data.shape_text.parse_shape_sentence``) or, failing that,
the adjectives of ``data.shape_text`` ("a tall, heavy-set man") mapped to the middle of their bands.
"""
from __future__ import annotations

import re

import numpy as np

from ..errors import ShapeMoveError
from .measure import MEASUREMENTS, measure_mesh
from .skeleton import JOINT_INDEX as JI

REG = 0.01            # cm^2 per unit beta^2: a 1-beta move is worth 0.1 cm of mismatch
FD_STEP = 0.5         # finite-difference step in betas (a secant over the girths' kinks)
BETA_LIMIT = 5.0      # the shape space is ~N(0,1); CLI --betas accepts [-5, 5] too
TOLERANCE_CM = 0.2    # stop when every target is this close
MAX_ITERS = 12
CHEAP = ("height_cm", "arm_length_cm", "leg_length_cm")
PLAUSIBLE_CM = {"height_cm": (50, 260), "chest_cm": (40, 200), "waist_cm": (30, 200), "hip_cm": (40, 200),
                "arm_length_cm": (15, 110), "leg_length_cm": (30, 140)}

# adjectives of data.shape_text -> the middle of their band (height cm; waist-to-height ratio)
HEIGHT_WORDS = {"very short": 150.0, "short": 160.0, "very tall": 195.0, "tall": 185.0}
BUILD_WORDS = {"very heavy": 0.64, "heavy-set": 0.565, "heavyset": 0.565, "heavy": 0.565, "slim": 0.41,
               "average-sized": None, "average": None}


def _path(joints: np.ndarray, names) -> np.ndarray:
    """(B,24,3) joints -> (B,) length of the joint path through ``names``."""
    p = joints[:, [JI[n] for n in names]]
    return np.linalg.norm(np.diff(p, axis=1), axis=-1).sum(1)


def fast_measure(body, betas: np.ndarray, keys) -> np.ndarray:
    """(B,10) betas -> (B, len(keys)) measurements in cm, as ``measure`` defines them; height and
    limb lengths straight from the rest vertices/joints (batched), girths via ``measure_mesh``."""
    import torch

    b = torch.as_tensor(np.asarray(betas, np.float32).reshape(-1, body.num_betas))
    with torch.no_grad():
        verts = body.rest_vertices(b).double().numpy()
        joints = body.rest_joints(b).double().numpy()
    floor = verts[..., 1].min(1)
    cols = []
    for k in keys:
        if k == "height_cm":
            v = verts[..., 1].max(1) - floor
        elif k == "arm_length_cm":
            v = np.mean([_path(joints, [f"{s}_shoulder", f"{s}_elbow", f"{s}_wrist"]) for s in ("left", "right")], 0)
        elif k == "leg_length_cm":
            v = np.mean([_path(joints, [f"{s}_hip", f"{s}_knee", f"{s}_ankle"]) + joints[:, JI[f"{s}_ankle"], 1] - floor
                         for s in ("left", "right")], 0)
        else:
            cols.append(None)
            continue
        cols.append(100.0 * v)
    if any(c is None for c in cols):
        rows = [measure_mesh(v, body.faces, j) for v, j in zip(verts, joints)]
        cols = [c if c is not None else np.array([r[k] for r in rows]) for c, k in zip(cols, keys)]
    return np.stack(cols, 1)


def _check_targets(targets: dict) -> dict:
    if not isinstance(targets, dict) or not targets:
        raise ShapeMoveError("no target measurements given (e.g. {'height_cm': 190})")
    out = {}
    for k, v in targets.items():
        if k not in MEASUREMENTS:
            raise ShapeMoveError(f"unknown measurement {k!r}; use {', '.join(MEASUREMENTS)}")
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise ShapeMoveError(f"measurement {k} must be a number of cm, got {v!r}") from None
        lo, hi = PLAUSIBLE_CM[k]
        if not (np.isfinite(v) and lo <= v <= hi):
            raise ShapeMoveError(f"{k} = {v} cm is outside the plausible range [{lo}, {hi}] cm")
        out[k] = v
    return out


def betas_for_measurements(body, targets: dict, reg: float = REG, max_iters: int = MAX_ITERS,
                           tolerance_cm: float = TOLERANCE_CM) -> np.ndarray:
    """(10,) float32 betas of ``body`` whose measurements (cm) best match ``targets``
    ({measurement name: cm}, any subset of ``measure.MEASUREMENTS``), near 0 where unconstrained.
    Targets the shape space can't reach give the closest body within |beta| <= BETA_LIMIT."""
    targets = _check_targets(targets)
    keys = list(targets)
    t = np.array([targets[k] for k in keys])
    n = body.num_betas
    b = np.zeros(n)
    probe = np.vstack([b, b + FD_STEP * np.eye(n)])           # one batch: base + one step per beta
    m_all = fast_measure(body, probe, keys)
    m = m_all[0]
    J = (m_all[1:] - m).T / FD_STEP                            # (K, 10) cm per unit beta
    cost = float(((m - t) ** 2).sum() + reg * b @ b)
    lam = 1e-3
    for _ in range(max_iters):
        if np.abs(m - t).max() < tolerance_cm:
            break
        H = J.T @ J + reg * np.eye(n)
        g = J.T @ (m - t) + reg * b
        step = np.linalg.solve(H + lam * np.diag(np.diag(H)), -g)
        b_new = np.clip(b + step, -BETA_LIMIT, BETA_LIMIT)
        m_new = fast_measure(body, b_new[None], keys)[0]
        s = b_new - b
        if s @ s > 1e-12:                                     # Broyden: J s must reproduce the change seen
            J = J + np.outer(m_new - m - J @ s, s) / (s @ s)
        cost_new = float(((m_new - t) ** 2).sum() + reg * b_new @ b_new)
        if cost_new < cost:
            b, m, cost, lam = b_new, m_new, cost_new, max(lam / 10, 1e-7)
        else:
            lam *= 10
        if np.abs(s).max() < 1e-4:
            break
    return b.astype(np.float32)


def targets_from_shape_text(text: str, body=None) -> dict:
    """Shape text -> target measurements (cm). Numbers win ("standing 190 cm tall, with a waist
    circumference of 100 cm"); otherwise height/build adjectives ("a tall, heavy-set man") give
    the middle of their ``data.shape_text`` band (build = waist-to-height ratio, at the stated
    height or the body's mean height). ShapeMoveError when the text states neither."""
    from ..data.shape_text import parse_shape_sentence

    if not isinstance(text, str) or not text.strip():
        raise ShapeMoveError("the shape text is empty")
    found = parse_shape_sentence(text)
    if found:
        return _check_targets(found)
    low = " " + re.sub(r"[^a-z\- ]+", " ", text.lower()) + " "
    height = next((v for w, v in HEIGHT_WORDS.items() if f" {w} " in low), None)
    build = [w for w in BUILD_WORDS if f" {w} " in low]
    if height is None and not build:
        raise ShapeMoveError(f"cannot read a body shape from {text!r}: state measurements (\"A person standing "
                             "180 cm tall, with a waist circumference of 90 cm\") or use words such as "
                             + ", ".join(list(HEIGHT_WORDS) + ["slim", "heavy-set", "very heavy", "average-sized"]))
    out = {}
    if height is not None:
        out["height_cm"] = height
    ratio = BUILD_WORDS[build[0]] if build else None
    if ratio is not None:
        if height is None:
            if body is None:
                from .load import load_body_model

                body = load_body_model(None)
            height = float(fast_measure(body, np.zeros((1, body.num_betas)), ["height_cm"])[0, 0])
            out["height_cm"] = height
        out["waist_cm"] = ratio * height
    return out


def betas_from_shape_text(body, text: str) -> np.ndarray:
    """(10,) betas of ``body`` for a shape text (see ``targets_from_shape_text``); an
    "average-sized" text with no height gives the mean body (zeros)."""
    targets = targets_from_shape_text(text, body)
    if not targets:
        return np.zeros(body.num_betas, np.float32)
    return betas_for_measurements(body, targets)
