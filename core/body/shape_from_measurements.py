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

Mass (kg) and BMI are measurements too: the closed mesh's volume x 985 kg/m^3 (``body_mass``),
an exact cubic in the betas (``fast_mass``).

Shape text -> body (``betas_for_shape_text``): ``text.shape_words`` reads the words and numbers
("a muscular 188 cm man, 92 kg", "an elderly woman", "6 ft 4, 250 lb"). On OpenBody the words set
the phenotype sliders through the shipped map (gender, age and muscle held exactly, weight, height
and proportions as a prior) and the stated numbers (height, girths, mass or BMI; size words' bands)
are then met on the mesh by Levenberg-Marquardt over the free sliders and the four beta directions
the sliders cannot see (``_phenotype_frame``), so the sliders read back from the betas are the
words' own. A stated height or weight the body cannot reach, or a result whose BMI a weight word
excludes, is a ShapeMoveError; so is every contradiction the reader finds. Bodies without a
phenotype map (the SMPL family) fit the numbers alone. ``shape_targets`` /
``targets_from_shape_text`` give the measurement targets of a text.
"""
from __future__ import annotations

import hashlib
import re
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..errors import ShapeMoveError
from ..text.shape_words import PERSON_RANGES, ShapeWords, parse_shape_words, size_targets, word_conflict
from .body_mass import DENSITY_KG_M3, VolumePolynomial, bmi as bmi_of
from .measure import MASS, MEASUREMENTS, measure_mesh
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
_volumes: dict = {}  # id(body) -> (body, VolumePolynomial)
PLAUSIBLE_CM = {"height_cm": (50, 260), "chest_cm": (40, 200), "waist_cm": (30, 200), "hip_cm": (40, 200),
                "arm_length_cm": (15, 110), "leg_length_cm": (30, 140),
                "mass_kg": PERSON_RANGES["mass_kg"], "bmi": PERSON_RANGES["bmi"]}
UNITS = {"mass_kg": "kg", "bmi": "kg/m^2"}


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
    return _linear_vertices(body)[:4]


def _linear_vertices(body) -> tuple:
    """``_linear_arrays`` plus the whole rest vertices: v0 (V,3), vdirs (V*3, n)."""
    entry = _arrays.get(id(body))
    if entry is None or entry[0] is not body:
        with torch_no_grad():
            y0 = body.v_template[:, 1].double().numpy()
            yd = body.shapedirs[:, 1, :].double().numpy()
            j0 = body.joint_template.double().numpy()
            jd = body.joint_shapedirs.double().numpy()
            v0 = body.v_template.double().numpy()
            vd = body.shapedirs.double().numpy().reshape(-1, body.num_betas)
        entry = (body, (y0, yd, j0, jd, v0, vd))
        _arrays[id(body)] = entry
    return entry[1]


def fast_mass(body, betas: np.ndarray) -> np.ndarray:
    """(B,10) betas -> (B,) mass in kg: the rest mesh's volume x ``body_mass.DENSITY_KG_M3``, the
    same number ``measure`` gives, from the volume's exact cubic in the betas (``VolumePolynomial``,
    built once per body)."""
    b = np.asarray(betas, np.float64).reshape(-1, body.num_betas)
    entry = _volumes.get(id(body))
    if entry is None or entry[0] is not body:
        _, _, _, _, v0, vd = _linear_vertices(body)
        entry = _volumes[id(body)] = (body, VolumePolynomial(v0, vd.reshape(*v0.shape, -1), body.faces))
    return entry[1](b) * DENSITY_KG_M3


def torch_no_grad():
    import torch

    return torch.no_grad()


def fast_measure(body, betas: np.ndarray, keys, girths: GirthRegression | None = None) -> np.ndarray:
    """(B,10) betas -> (B, len(keys)) measurements in cm (mass_kg in kg, bmi in kg/m^2), as
    ``measure`` defines them; height and limb lengths straight from the rest vertices/joints
    (linear in the betas, batched), mass from the mesh volume (``fast_mass``), girths via
    ``measure_mesh``, or from the regression ``girths`` when given."""
    b = np.asarray(betas, np.float64).reshape(-1, body.num_betas)
    y0, yd, j0, jd = _linear_arrays(body)
    ys = y0[None] + b @ yd.T                                   # (B,V) vertex heights
    joints = j0[None] + np.einsum("jcn,bn->bjc", jd, b)        # (B,24,3)
    floor = ys.min(1)
    cols = []
    mass = fast_mass(body, b) if ("mass_kg" in keys or "bmi" in keys) else None
    for k in keys:
        if k in ("mass_kg", "bmi"):
            cols.append(mass if k == "mass_kg" else bmi_of(mass, 100.0 * (ys.max(1) - floor)))
            continue
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
        if k not in MEASUREMENTS + MASS:
            raise ShapeMoveError(f"unknown measurement {k!r}; use {', '.join(MEASUREMENTS + MASS)}")
        unit = UNITS.get(k, "cm")
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise ShapeMoveError(f"measurement {k} must be a number of {unit}, got {v!r}") from None
        lo, hi = PLAUSIBLE_CM[k]
        if not (np.isfinite(v) and lo <= v <= hi):
            raise ShapeMoveError(f"{k} = {v} {unit} is outside the plausible range [{lo}, {hi}] {unit}")
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


# ----------------------------------------------------------------------------------------------
# shape text -> body: phenotype words set the sliders, stated numbers are met on the mesh

STATED_TOLERANCE = {"height_cm": 1.0, "mass_kg": 2.0, "bmi": 0.7}  # a stated number missed by more: refused
ERROR_UNIT = {"mass_kg": 1.0, "bmi": 0.3}      # residual scale (cm for the rest): 1 kg ~ 1 cm, 0.3 BMI ~ 1 cm
SLIDER_SIGMA = {"gender": 0.3, "age": 15.0, "muscle": 0.25, "weight": 0.25, "height": 0.08, "proportions": 0.25}
SLIDER_EXTRA = 0.6   # free sliders may extrapolate this share of their range beyond it (gender: none)
FIXED_BY_WORDS = ("gender", "age", "muscle")   # set by words, held exactly (their read-back is exact)
RESIDUAL_LIMIT = 3.0


def shape_words(text: str) -> ShapeWords:
    """The parsed shape text (``text.shape_words.parse_shape_words``), with the text's errors
    named: empty text, contradictions, impossible numbers."""
    if not isinstance(text, str) or not text.strip():
        raise ShapeMoveError("the shape text is empty")
    try:
        return parse_shape_words(text)
    except ShapeMoveError as exc:
        raise ShapeMoveError(f"the shape text {text!r}: {exc}") from None


def _targets(d: ShapeWords, default_height) -> dict:
    """Target measurements of a parsed text: stated numbers win; size words give a height and a
    waist (ratio x height; ``default_height()`` when the text gives none); weight words that are no
    size word ("obese", "skinny") a BMI when no weight is stated."""
    out = d.measurements()
    h_word, ratio = size_targets(d)
    if "height_cm" not in out and h_word is not None:
        out["height_cm"] = h_word
    if d.mass_kg is not None:
        out["mass_kg"] = d.mass_kg
    elif d.bmi is not None:
        out["bmi"] = d.bmi
    elif d.bmi_target() is not None:
        out["bmi"] = d.bmi_target()
    weight_stated = d.mass_kg is not None or d.bmi is not None
    if ratio is not None and "waist_cm" not in out and not weight_stated:
        out["waist_cm"] = ratio * (out["height_cm"] if "height_cm" in out else default_height())
    return out


def shape_targets(text: str, body=None) -> dict | None:
    """Shape text -> target measurements (cm; mass_kg in kg, bmi), or None when it states neither
    numbers nor any shape word (free text: the [BETA] head reads it). {} when it has shape words
    but no measurement to aim at ("a man", "an average-sized person"). Numbers it states must be
    plausible: "5000 cm tall", "waist 0 cm", "-170 cm", "weighs 900 kg" or a contradiction are a
    ShapeMoveError naming them, never ignored."""
    d = shape_words(text)
    if not d:
        return None

    def default_height():
        b = body
        if b is None:
            from .load import load_body_model

            b = load_body_model(None)
        return float(fast_measure(b, start_betas(b, d)[None], ["height_cm"])[0, 0])

    try:
        raw = _targets(d, default_height)
        return _check_targets(raw) if raw else {}
    except ShapeMoveError as exc:
        raise ShapeMoveError(f"the shape text {text!r}: {exc}") from None


def targets_from_shape_text(text: str, body=None) -> dict:
    """Shape text -> target measurements (cm) as ``shape_targets``; ShapeMoveError when the text
    has no shape word or number at all."""
    out = shape_targets(text, body)
    if out is None:
        raise ShapeMoveError(f"cannot read a body shape from {text!r}: state measurements (\"180 cm tall, 75 kg\", "
                             "\"6 ft 2, 200 lb\", \"waist 90 cm\") or use words such as man, woman, elderly, young, "
                             "muscular, slim, overweight, tall, short, heavy-set")
    return out


def start_betas(body, d: ShapeWords) -> np.ndarray:
    """The body the words describe before any number is met: OpenBody's sliders at their defaults,
    with the ones the words set (gender, age, muscle, weight) -> (10,) float64 betas; zeros for a
    body without a phenotype map (the SMPL family) or a text without phenotype words."""
    pmap = getattr(body, "phenotype_map", None)
    if pmap is None or not d.phenotype():
        return np.zeros(body.num_betas)
    return pmap.to_betas(d.phenotype())


def _phenotype_frame(pmap, d: ShapeWords):
    """The fit's parametrisation for a phenotype body: betas(theta) = base + theta @ A, theta the
    free sliders then 4 coordinates along the null space of the map (moves the read-back of
    the sliders cannot see), so the sliders the words fixed read back exactly."""
    names = pmap.names
    p0 = pmap.array(d.phenotype())
    fixed = [i for i, n in enumerate(names) if n in FIXED_BY_WORDS and n in d.phenotype()]
    free = [i for i in range(len(names)) if i not in fixed]
    _, _, vt = np.linalg.svd(pmap.matrix)
    null = vt[len(names):]                                  # (10-P, 10), orthonormal, matrix @ null.T = 0
    A = np.vstack([pmap.matrix[free], null])                # (k, 10)
    base = pmap.to_betas(p0) - p0[free] @ pmap.matrix[free]
    mu = np.concatenate([p0[free], np.zeros(len(null))])
    sigma = np.array([SLIDER_SIGMA.get(names[i], 0.25) for i in free] + [1.0] * len(null))
    lo, hi = pmap.ranges[:, 0], pmap.ranges[:, 1]
    ext = np.where(np.array(names) == "gender", 0.0, SLIDER_EXTRA) * (hi - lo)
    lo_b = np.concatenate([(lo - ext)[free], -RESIDUAL_LIMIT * np.ones(len(null))])
    hi_b = np.concatenate([(hi + ext)[free], RESIDUAL_LIMIT * np.ones(len(null))])
    return base, A, mu, sigma, lo_b, hi_b


def _fit_frame(body, targets: dict, base, A, mu, sigma, lo_b, hi_b, reg: float = REG, iters: int = 30) -> np.ndarray:
    """Levenberg-Marquardt over theta: min sum ((m(base + theta A) - t) / unit)^2 + reg |(theta - mu)
    / sigma|^2, theta inside [lo_b, hi_b]; forward-difference Jacobian (one batch per step)."""
    keys = list(targets)
    girths = girth_regression(body)
    t = np.array([targets[k] for k in keys])
    unit = np.array([ERROR_UNIT.get(k, 1.0) for k in keys])
    w = np.sqrt(reg) / sigma
    theta = np.clip(mu.copy(), lo_b, hi_b)
    h = 1e-3 * np.maximum(sigma, 1e-3) * 10

    def residual(th, m):
        return np.concatenate([(m - t) / unit, w * (th - mu)])

    def meas(ths):
        return fast_measure(body, base[None] + ths @ A, keys, girths)

    if not keys:
        return base + theta @ A
    m = meas(theta[None])[0]
    r = residual(theta, m)
    cost, lam = float(r @ r), 1e-3
    for _ in range(iters):
        probe = theta[None] + np.diag(h)
        mp = meas(probe)
        J = np.vstack([((mp - m) / h[:, None] / unit[None]).T, np.diag(w)])
        H = J.T @ J
        g = J.T @ r
        improved = False
        for _ in range(8):
            step = np.linalg.solve(H + lam * (np.diag(np.diag(H)) + 1e-9 * np.eye(len(H))), -g)
            th_new = np.clip(theta + step, lo_b, hi_b)
            m_new = meas(th_new[None])[0]
            r_new = residual(th_new, m_new)
            c_new = float(r_new @ r_new)
            if c_new < cost:
                theta, m, r, cost, lam, improved = th_new, m_new, r_new, c_new, max(lam / 10, 1e-9), True
                break
            lam *= 10
        if not improved or np.abs((m - t) / unit).max() < 0.02 or np.abs(step).max() < 1e-5:
            break
    return base + theta @ A


def betas_for_shape_words(body, d: ShapeWords) -> np.ndarray:
    """(10,) float32 betas for a parsed shape text. On OpenBody the words set the phenotype
    sliders (gender, age, muscle held exactly; weight, height, proportions as a prior) and the
    stated numbers (height, girths, mass or BMI) are then met on the mesh by moving the free
    sliders and the shape directions the sliders do not reach; other bodies (no phenotype map)
    fit the numbers alone (``betas_for_measurements``). A stated height or weight the body cannot
    reach, or a weight word the result contradicts, is a ShapeMoveError naming it."""
    pmap = getattr(body, "phenotype_map", None)
    start = start_betas(body, d)
    raw = _targets(d, lambda: float(fast_measure(body, start[None], ["height_cm"])[0, 0]))
    targets = _check_targets(raw) if raw else {}
    if pmap is None or not d.phenotype():
        betas = betas_for_measurements(body, targets) if targets else np.zeros(body.num_betas, np.float32)
    else:
        frame = _phenotype_frame(pmap, d)
        betas = _fit_frame(body, targets, *frame).astype(np.float32)
    _check_result(body, d, targets, betas)
    return betas


def _describe(d: ShapeWords) -> str:
    return d.text.strip() or "this body"


def _check_result(body, d: ShapeWords, targets: dict, betas: np.ndarray) -> None:
    """The stated height and weight met (``STATED_TOLERANCE``), the betas inside the shape space,
    the weight words agreeing with the result's BMI; else a ShapeMoveError saying what is missed."""
    if np.abs(betas).max() > BETA_LIMIT:
        raise ShapeMoveError(f"{_describe(d)!r} lies outside the body model's shape space (|beta| "
                             f"{np.abs(betas).max():.1f} > {BETA_LIMIT:g}): ask for a less extreme body")
    stated = {k: v for k, v in targets.items() if k in STATED_TOLERANCE and (
        (k == "height_cm" and d.height_cm is not None) or (k == "mass_kg" and d.mass_kg is not None)
        or (k == "bmi" and d.bmi is not None))}
    got = fast_measure(body, betas[None], list(stated) + ["height_cm", "mass_kg", "bmi"])[0]
    for i, (k, v) in enumerate(stated.items()):
        if abs(got[i] - v) > STATED_TOLERANCE[k]:
            unit = UNITS.get(k, "cm")
            raise ShapeMoveError(f"the body model cannot make {_describe(d)!r}: {k.replace('_cm', '').replace('_kg', '')} "
                                 f"{v:.1f} {unit} asked, {got[i]:.1f} {unit} is the closest it reaches with the rest "
                                 "of the description (height and weight together decide the build)")
    bmi = got[-1]
    band = d.bmi_band()
    if band is not None and (d.mass_kg is not None or d.bmi is not None) and not band[0] - 0.5 <= bmi <= band[1] + 0.5:
        raise ShapeMoveError(f"the shape text {_describe(d)!r} contradicts itself: its body has BMI {bmi:.1f} "
                             f"({got[-3]:.0f} cm, {got[-2]:.0f} kg)" + word_conflict(d, bmi))


def betas_for_shape_text(body, text: str) -> np.ndarray | None:
    """(10,) betas of ``body`` for a shape text, or None when the text has no shape word or number
    (free text: the [BETA] head's to read). See ``betas_for_shape_words``."""
    d = shape_words(text)
    if not d:
        return None
    try:
        return betas_for_shape_words(body, d)
    except ShapeMoveError as exc:
        msg = str(exc)
        raise ShapeMoveError(msg if text in msg else f"the shape text {text!r}: {msg}") from None


def betas_from_shape_text(body, text: str) -> np.ndarray:
    """(10,) betas of ``body`` for a shape text (``betas_for_shape_text``); ShapeMoveError when
    the text has no shape word or number. An "average-sized person" is the mean body (zeros)."""
    betas = betas_for_shape_text(body, text)
    if betas is None:
        targets_from_shape_text(text, body)  # raises, saying what the text may say
    return betas
