"""Betas from body measurements or a shape text: the inverse of ``measure``.

``betas_for_measurements(body, {"height_cm": 190, "waist_cm": 100})`` finds betas whose
``measure(body, betas)`` matches the stated numbers, by Levenberg-Marquardt on

    sum_k (m_k(b) - target_k)^2  +  REG |b|^2          (m in cm, b ~ N(0,1))

``measure`` slices the mesh and is not differentiable, so the Jacobian is taken by finite
differences (once at the start, then updated by Broyden's rank-one rule, so a step costs one
measurement). Height and arm/leg lengths only need the rest vertices and joints and are computed
directly here (milliseconds, batched; ``fast_measure`` checks against ``measure`` in the tests).
Girths (chest, waist, hip) would need ``measure_mesh`` (~0.1-0.4 s each); for a body with a
precomputed ``GirthRegression`` (OpenBody: ``assets/girth_regression.npz``, built by
``tools/build_girth_regression.py``) they come from a quadratic regression betas -> girths fitted
on mesh measurements of sampled bodies (the tests check it against ``measure``), so a whole fit
costs a few milliseconds; other bodies use the mesh. The prior keeps the directions the targets
don't constrain near 0, so "190 cm tall" changes height without inventing a belly.

``targets_from_shape_text`` reads a numeric shape sentence ("A person standing 190 cm tall, with
a waist circumference of 100 cm ...", ``data.shape_text.parse_shape_sentence``) or, failing that,
the adjectives of ``data.shape_text`` ("a tall, heavy-set man") mapped to the middle of their bands.
"""
from __future__ import annotations

import hashlib
import re
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..data.shape_text import parse_shape_sentence
from ..errors import ShapeMoveError
from .measure import MEASUREMENTS, measure_mesh
from .skeleton import JOINT_INDEX as JI

REG = 0.01            # cm^2 per unit beta^2: a 1-beta move is worth 0.1 cm of mismatch
FD_STEP = 0.5         # finite-difference step in betas (a secant over the girths' kinks)
BETA_LIMIT = 5.0      # the shape space is ~N(0,1); CLI --betas accepts [-5, 5] too
TOLERANCE_CM = 0.2    # stop when every target is this close
MAX_ITERS = 12
CHEAP = ("height_cm", "arm_length_cm", "leg_length_cm")
GIRTHS = ("chest_cm", "waist_cm", "hip_cm")
REGRESSION_FILE = Path(__file__).resolve().parents[2] / "assets" / "girth_regression.npz"
_regressions: dict = {}
_keys: dict = {}     # id(body) -> (body, body_key): the key is computed once per body object
_arrays: dict = {}   # id(body) -> (body, linear arrays of fast_measure)
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


def quad_features(betas: np.ndarray) -> np.ndarray:
    """(B,n) -> (B, 1 + n + n(n+1)/2): constant, linear and all quadratic terms."""
    b = np.asarray(betas, np.float64).reshape(len(betas), -1)
    i, j = np.triu_indices(b.shape[1])
    return np.concatenate([np.ones((len(b), 1)), b, b[:, i] * b[:, j]], 1)


def body_key(body) -> str:
    """Identifies a body's shape space: sha256 of its rest vertices for betas 0 and each unit beta
    (rounded to 0.01 mm), so a regression is never used with another body."""
    import torch

    with torch.no_grad():
        v = body.rest_vertices(np.vstack([np.zeros(body.num_betas), np.eye(body.num_betas)]).astype(np.float32))
    return hashlib.sha256(np.round(v.double().numpy() * 1e5).astype(np.int64).tobytes()).hexdigest()


class GirthRegression:
    """Quadratic regression betas -> (chest, waist, hip) girths in cm for one body."""

    def __init__(self, coef: np.ndarray, key: str, rms_cm: np.ndarray):
        self.coef, self.key, self.rms_cm = np.asarray(coef, np.float64), str(key), np.asarray(rms_cm, np.float64)

    def predict(self, betas: np.ndarray, keys=GIRTHS) -> np.ndarray:
        """(B,10) -> (B, len(keys)) cm."""
        out = quad_features(betas) @ self.coef
        return out[:, [GIRTHS.index(k) for k in keys]]

    def save(self, path: Path) -> None:
        with atomic_path(path, suffix=".npz") as tmp:
            np.savez(tmp, coef=self.coef, key=np.array(self.key), rms_cm=self.rms_cm, girths=np.array(GIRTHS))

    @classmethod
    def load(cls, path: Path) -> "GirthRegression":
        try:
            with np.load(path, allow_pickle=False) as z:
                reg = cls(z["coef"], str(z["key"]), z["rms_cm"])
                names = tuple(str(g) for g in z["girths"])
        except (OSError, ValueError, KeyError) as exc:
            raise ShapeMoveError(f"{path}: not a girth regression file ({exc})") from None
        if names != GIRTHS or reg.coef.ndim != 2 or reg.coef.shape[1] != len(GIRTHS):
            raise ShapeMoveError(f"{path}: girth regression of another layout {names} {reg.coef.shape}")
        return reg


def fit_girth_regression(body, samples: int = 400, seed: int = 0, progress: bool = False) -> GirthRegression:
    """Measure ``samples`` sampled bodies on the mesh (betas ~ N(0,1), a third of them ~ N(0,2^2),
    clipped to the limit) and fit the quadratic regression by ridge least squares."""
    import torch
    from tqdm import tqdm

    rng = np.random.default_rng(seed)
    n = body.num_betas
    b = rng.standard_normal((samples, n)) * np.where(rng.random((samples, 1)) < 1 / 3, 2.0, 1.0)
    b = np.clip(b, -BETA_LIMIT, BETA_LIMIT)
    b[0] = 0.0
    with torch.no_grad():
        verts = body.rest_vertices(b.astype(np.float32)).double().numpy()
        joints = body.rest_joints(b.astype(np.float32)).double().numpy()
    y = []
    for v, j in tqdm(zip(verts, joints), total=samples, desc="measure bodies", unit="body", disable=not progress):
        m = measure_mesh(v, body.faces, j)
        y.append([m[k] for k in GIRTHS])
    y = np.asarray(y)
    ok = np.isfinite(y).all(1)
    X = quad_features(b[ok])
    coef = np.linalg.solve(X.T @ X + 1e-3 * np.eye(X.shape[1]), X.T @ y[ok])
    rms = np.sqrt(((X @ coef - y[ok]) ** 2).mean(0))
    return GirthRegression(coef, body_key(body), rms)


def girth_regression(body) -> GirthRegression | None:
    """The precomputed regression of ``body`` (OpenBody's ships in assets/), or None."""
    entry = _keys.get(id(body))
    if entry is None or entry[0] is not body:
        entry = _keys[id(body)] = (body, body_key(body))
    key = entry[1]
    if key not in _regressions:
        reg = GirthRegression.load(REGRESSION_FILE) if REGRESSION_FILE.is_file() else None
        _regressions[key] = reg if reg is not None and reg.key == key else None
    return _regressions[key]


def _linear_arrays(body) -> tuple:
    """Per body, once: the rest vertices' heights and the joints as linear functions of the betas
    (float64 numpy): y0 (V,), ydirs (V,n), j0 (24,3), jdirs (24,3,n)."""
    entry = _arrays.get(id(body))
    if entry is None or entry[0] is not body:
        with torch_no_grad():
            y0 = body.v_template[:, 1].double().numpy()
            yd = body.shapedirs[:, 1, :].double().numpy()
            j0 = body.joint_template.double().numpy()
            jd = body.joint_shapedirs.double().numpy()
        entry = (body, (y0, yd, j0, jd))
        _arrays[id(body)] = entry
    return entry[1]


def torch_no_grad():
    import torch

    return torch.no_grad()


def fast_measure(body, betas: np.ndarray, keys, girths: GirthRegression | None = None) -> np.ndarray:
    """(B,10) betas -> (B, len(keys)) measurements in cm, as ``measure`` defines them; height and
    limb lengths straight from the rest vertices/joints (linear in the betas, batched), girths via
    ``measure_mesh``, or from the regression ``girths`` when given."""
    b = np.asarray(betas, np.float64).reshape(-1, body.num_betas)
    y0, yd, j0, jd = _linear_arrays(body)
    ys = y0[None] + b @ yd.T                                   # (B,V) vertex heights
    joints = j0[None] + np.einsum("jcn,bn->bjc", jd, b)        # (B,24,3)
    floor = ys.min(1)
    cols = []
    for k in keys:
        if k == "height_cm":
            v = ys.max(1) - floor
        elif k == "arm_length_cm":
            v = np.mean([_path(joints, [f"{s}_shoulder", f"{s}_elbow", f"{s}_wrist"]) for s in ("left", "right")], 0)
        elif k == "leg_length_cm":
            v = np.mean([_path(joints, [f"{s}_hip", f"{s}_knee", f"{s}_ankle"]) + joints[:, JI[f"{s}_ankle"], 1] - floor
                         for s in ("left", "right")], 0)
        elif girths is not None:
            cols.append(girths.predict(b, [k])[:, 0])
            continue
        else:
            cols.append(None)
            continue
        cols.append(100.0 * v)
    if any(c is None for c in cols):
        import torch

        with torch.no_grad():
            verts = body.rest_vertices(torch.as_tensor(b, dtype=torch.float32)).double().numpy()
        rows = [measure_mesh(v, body.faces, j) for v, j in zip(verts, joints)]
        cols = [c if c is not None else np.array([r[k] for r in rows]) for c, k in zip(cols, keys)]
    return np.stack(cols, 1)


def torch_measure(body, keys=("height_cm", "waist_cm")):
    """A differentiable ``fast_measure``: a function (B,10) float tensor -> (B, len(keys)) cm, for
    height (top minus bottom of the rest mesh, linear in the betas) and the regression girths
    (chest, waist, hip; needs the body's ``GirthRegression``). Used as a training loss."""
    import torch

    bad = [k for k in keys if k != "height_cm" and k not in GIRTHS]
    if bad:
        raise ShapeMoveError(f"torch_measure: no differentiable measure for {bad} (height_cm and {', '.join(GIRTHS)})")
    girths = girth_regression(body) if any(k in GIRTHS for k in keys) else None
    if any(k in GIRTHS for k in keys) and girths is None:
        raise ShapeMoveError("torch_measure: this body has no girth regression (assets/girth_regression.npz is OpenBody's)")
    y0, yd, _, _ = _linear_arrays(body)
    Y0, YD = torch.as_tensor(y0, dtype=torch.float32), torch.as_tensor(yd, dtype=torch.float32)
    coef = torch.as_tensor(girths.coef, dtype=torch.float32) if girths is not None else None
    n = body.num_betas
    iu = torch.triu_indices(n, n)

    def measure(b):
        cols = []
        if "height_cm" in keys:
            ys = Y0.to(b.device)[None] + b @ YD.to(b.device).T
            height = 100.0 * (ys.max(1).values - ys.min(1).values)
        if coef is not None:
            q = torch.cat([torch.ones_like(b[:, :1]), b, b[:, iu[0]] * b[:, iu[1]]], 1)
            g = q @ coef.to(b.device)
        for k in keys:
            cols.append(height if k == "height_cm" else g[:, GIRTHS.index(k)])
        return torch.stack(cols, 1)

    return measure


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
                           tolerance_cm: float = TOLERANCE_CM, exact: bool = False) -> np.ndarray:
    """(10,) float32 betas of ``body`` whose measurements (cm) best match ``targets``
    ({measurement name: cm}, any subset of ``measure.MEASUREMENTS``), near 0 where unconstrained.
    Targets the shape space can't reach give the closest body within |beta| <= BETA_LIMIT.
    Girths come from the body's precomputed regression when it has one (milliseconds) unless
    ``exact`` (the mesh, ~1 s)."""
    targets = _check_targets(targets)
    girths = None if exact else girth_regression(body)
    keys = list(targets)
    t = np.array([targets[k] for k in keys])
    n = body.num_betas
    b = np.zeros(n)
    probe = np.vstack([b, b + FD_STEP * np.eye(n)])           # one batch: base + one step per beta
    m_all = fast_measure(body, probe, keys, girths)
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
        m_new = fast_measure(body, b_new[None], keys, girths)[0]
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


UNIT_NUMBER = re.compile(r"\d\s*(?:cm\b|centimet|m\b|met(?:er|re)s?\b|ft\b|feet\b|foot\b|inch|in\b|'|\")")
NEGATIVE = re.compile(r"(?<![\w.])[-\u2212]\s*\d")  # "-170 cm", "−2 m" (not "39-inch", "170-180")


def shape_targets(text: str, body=None) -> dict | None:
    """Shape text -> target measurements (cm), or None when it states neither numbers nor size
    words (free text: the [BETA] head reads it). Numbers it states must be plausible: "5000 cm
    tall", "waist 0 cm" or "-170 cm" are a ShapeMoveError naming the number, never ignored."""
    if not isinstance(text, str) or not text.strip():
        raise ShapeMoveError("the shape text is empty")
    neg = NEGATIVE.search(text)
    if neg:
        raise ShapeMoveError(f"the shape text states a negative number ({text[neg.start():neg.end() + 8].strip()!r}); "
                             "body measurements are positive, e.g. '170 cm tall'")
    found = parse_shape_sentence(text)
    if found:
        try:
            return _check_targets(found)
        except ShapeMoveError as exc:
            raise ShapeMoveError(f"the shape text {text!r}: {exc}") from None
    if UNIT_NUMBER.search(text.lower()):  # a number the parser could not place ("999 m tall"): never guessed
        raise ShapeMoveError(f"cannot read the measurements in {text!r}: write them as '182 cm tall', "
                             "'1.82 m tall', '6 ft 0 in tall' or 'waist 90 cm' (a person is 50-260 cm tall)")
    low = " " + re.sub(r"[^a-z\- ]+", " ", text.lower()) + " "
    height = next((v for w, v in HEIGHT_WORDS.items() if f" {w} " in low), None)
    build = [w for w in BUILD_WORDS if f" {w} " in low]
    if height is None and not build:
        return None
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


def targets_from_shape_text(text: str, body=None) -> dict:
    """Shape text -> target measurements (cm). Numbers win ("standing 190 cm tall, with a waist
    circumference of 100 cm"); otherwise height/build adjectives ("a tall, heavy-set man") give
    the middle of their ``data.shape_text`` band (build = waist-to-height ratio, at the stated
    height or the body's mean height). ShapeMoveError when the text states neither."""
    out = shape_targets(text, body)
    if out is None:
        raise ShapeMoveError(f"cannot read a body shape from {text!r}: state measurements (\"A person standing "
                             "180 cm tall, with a waist circumference of 90 cm\") or use words such as "
                             + ", ".join(list(HEIGHT_WORDS) + ["slim", "heavy-set", "very heavy", "average-sized"]))
    return out


def betas_from_shape_text(body, text: str) -> np.ndarray:
    """(10,) betas of ``body`` for a shape text (see ``targets_from_shape_text``); an
    "average-sized" text with no height gives the mean body (zeros)."""
    targets = targets_from_shape_text(text, body)
    if not targets:
        return np.zeros(body.num_betas, np.float32)
    return betas_for_measurements(body, targets)
