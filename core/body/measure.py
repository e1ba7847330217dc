"""Body measurements on the rest-pose mesh of any BodyModel (centimetres).

``measure(body, betas)`` returns height, chest/waist/hip circumferences, arm and leg lengths.
Circumferences are tape-measure girths: the mesh is cut by a horizontal plane, the closed loop
of the trunk is kept (the loop around the spine axis; arms are separate loops and dropped) and the
perimeter of its convex hull is taken. The levels are located from the joints, so the same code
serves OpenBody and the SMPL family:

- waist: smallest girth between 25% and 60% of the hip-to-shoulder span above the hip joints,
- chest: largest girth between 55% and 80% of that span (below the armpits),
- hip:   largest girth from 12% below to 15% above the hip joints (buttocks; below the crotch
         the two thighs are measured together, as a tape around both would),
- arm length: shoulder -> elbow -> wrist joint path; leg length: hip -> knee -> ankle joint
  path plus the ankle height above the floor (lowest vertex); height: top minus lowest vertex;
- mass (kg): the closed mesh's volume x a whole-body density, and BMI (kg/m^2) from that mass and
  the height (``body_mass``: the density and its source).

``format_body(m)`` is the one-line readout the command line prints ("height 175 cm, ..., mass 76
kg, BMI 24.6").
"""
from __future__ import annotations

import weakref

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, QhullError

from ..errors import ShapeMoveError
from .body_mass import bmi, mass_kg
from .skeleton import JOINT_INDEX as JI

MEASUREMENTS = ["height_cm", "chest_cm", "waist_cm", "hip_cm", "arm_length_cm", "leg_length_cm"]  # cm
MASS = ["mass_kg", "bmi"]  # kg, kg/m^2
_LEVELS = 16  # levels scanned per band


def cross_section(vertices: np.ndarray, faces: np.ndarray, y: float) -> list[np.ndarray]:
    """Cut a triangle mesh by the plane Y=y. vertices (V,3), faces (F,3).
    Returns the connected pieces of the section, each an (S,2,2) array of segments in (x, z)."""
    d = vertices[:, 1] - y
    d = np.where(d == 0, 1e-12, d)  # vertices on the plane count as above it
    above = d[faces] > 0
    mixed = above.any(1) & ~above.all(1)
    f = faces[mixed]
    if len(f) == 0:
        return []
    edges = np.stack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]], 1)  # (M,3,2)
    a, b = edges[..., 0], edges[..., 1]
    crosses = (d[a] > 0) != (d[b] > 0)  # exactly two per mixed face
    a, b = a[crosses].reshape(-1, 2), b[crosses].reshape(-1, 2)
    t = (d[a] / (d[a] - d[b]))[..., None]
    pts = vertices[a] + t * (vertices[b] - vertices[a])  # (M,2,3)
    segs = pts[..., [0, 2]]
    # connect segments that share a mesh edge
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    keys = lo.astype(np.int64) * (len(vertices) + 1) + hi
    _, node = np.unique(keys.ravel(), return_inverse=True)
    node = node.reshape(-1, 2)
    n = int(node.max()) + 1
    g = coo_matrix((np.ones(len(node)), (node[:, 0], node[:, 1])), shape=(n, n))
    _, label = connected_components(g, directed=False)
    comp = label[node[:, 0]]
    return [segs[comp == c] for c in np.unique(comp)]


def contains(segments: np.ndarray, point) -> bool:
    """Even-odd rule: is the (x, z) point inside the closed loop(s) made of these segments?"""
    p = np.asarray(point, dtype=np.float64)
    (x0, z0), (x1, z1) = segments[:, 0].T, segments[:, 1].T
    straddle = (z0 > p[1]) != (z1 > p[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        x_at = x0 + (p[1] - z0) * (x1 - x0) / (z1 - z0)
    return bool(np.count_nonzero(straddle & (x_at > p[0])) % 2)


def hull_perimeter(points: np.ndarray) -> float:
    """Perimeter of the 2D convex hull of (N,2) points (a tape measure's length)."""
    if len(points) < 3:
        return 0.0
    try:
        hull = ConvexHull(points)
    except QhullError:
        return 0.0
    ring = points[hull.vertices]
    return float(np.linalg.norm(ring - np.roll(ring, 1, axis=0), axis=1).sum())


def girth(vertices, faces, y: float, inside_points) -> float:
    """Convex-hull perimeter (metres) of the section pieces at Y=y that enclose one of the
    (x, z) inside_points; 0 when none does."""
    section = cross_section(vertices, faces, y)
    pieces = [s for s in section if any(contains(s, p) for p in inside_points)]
    if not pieces and section:
        # a thin body can have its spine joint just outside the skin: take the piece closest to it
        # (within 10 cm), never an arm
        p0 = np.asarray(inside_points[0], np.float64)
        dist = [np.linalg.norm(np.asarray(s).reshape(-1, 2) - p0, axis=1).min() for s in section]
        if min(dist) < 0.10:
            pieces = [section[int(np.argmin(dist))]]
    if not pieces:
        return 0.0
    return hull_perimeter(np.concatenate(pieces).reshape(-1, 2))


def _axis_point(joints: np.ndarray, y: float) -> np.ndarray:
    """(x, z) of the spine (pelvis-spine1-spine2-spine3-neck polyline) at height y."""
    chain = joints[[JI["pelvis"], JI["spine1"], JI["spine2"], JI["spine3"], JI["neck"]]]
    ys = chain[:, 1]
    order = np.argsort(ys)
    return np.array([np.interp(y, ys[order], chain[order, k]) for k in (0, 2)])


def _band(vertices, faces, joints, lo: float, hi: float, pick, extra=()) -> float:
    levels = np.linspace(lo, hi, _LEVELS)
    values = [girth(vertices, faces, y, [_axis_point(joints, y), *extra]) for y in levels]
    values = [v for v in values if v > 0]
    return pick(values) if values else float("nan")


def _path(joints, names) -> float:
    idx = [JI[n] for n in names]
    return float(np.linalg.norm(np.diff(joints[idx], axis=0), axis=1).sum())


def measure_mesh(vertices: np.ndarray, faces: np.ndarray, joints: np.ndarray) -> dict:
    """Measurements (cm) of one rest-pose mesh: vertices (V,3) metres Y up, faces (F,3),
    joints (24,3) SMPL order."""
    v, j = np.asarray(vertices, np.float64), np.asarray(joints, np.float64)
    hip_y = j[[JI["left_hip"], JI["right_hip"]], 1].mean()
    span = j[[JI["left_shoulder"], JI["right_shoulder"]], 1].mean() - hip_y
    if not span > 0:
        raise ShapeMoveError("cannot measure: the shoulders are not above the hips (is the body in its rest pose?)")
    floor = v[:, 1].min()
    thighs = [j[JI[n]][[0, 2]] for n in ("left_hip", "right_hip")]
    out = {
        "height_cm": (v[:, 1].max() - floor),
        "chest_cm": _band(v, faces, j, hip_y + 0.55 * span, hip_y + 0.80 * span, max),
        "waist_cm": _band(v, faces, j, hip_y + 0.25 * span, hip_y + 0.60 * span, min),
        "hip_cm": _band(v, faces, j, hip_y - 0.12 * span, hip_y + 0.15 * span, max, thighs),
        "arm_length_cm": np.mean([_path(j, [f"{s}_shoulder", f"{s}_elbow", f"{s}_wrist"]) for s in ("left", "right")]),
        "leg_length_cm": np.mean([_path(j, [f"{s}_hip", f"{s}_knee", f"{s}_ankle"]) + j[JI[f"{s}_ankle"], 1] - floor
                                  for s in ("left", "right")]),
    }
    out = {k: float(100.0 * x) for k, x in out.items()}
    out["mass_kg"] = float(mass_kg(v, faces))
    out["bmi"] = float(bmi(out["mass_kg"], out["height_cm"]))
    return out


MEASURED_KEPT = 32   # single bodies' measurements kept per body model (a worker measures the same bodies again)
_MEASURED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def measure(body, betas=None) -> dict:
    """Measurements of ``body`` (any BodyModel) in its rest pose. betas (10,) or None -> dict of
    floats (keys MEASUREMENTS in cm, then MASS: kg and kg/m^2); betas (B,10) -> dict of (B,) float
    arrays."""
    b = np.zeros(body.num_betas, np.float32) if betas is None else np.asarray(betas, np.float32)
    if b.ndim not in (1, 2) or b.shape[-1] != body.num_betas or not np.all(np.isfinite(b)):
        raise ShapeMoveError(f"betas must be finite with shape ({body.num_betas},) or (B, {body.num_betas}), "
                             f"got {b.shape}")
    single = b.ndim == 1
    if single and b.tobytes() in _MEASURED.get(body, {}):   # the same body measured again: read back
        return dict(_MEASURED[body][b.tobytes()])
    b2 = b[None] if single else b
    verts = body.rest_vertices(b2).detach().cpu().numpy()
    joints = body.rest_joints(b2).detach().cpu().numpy()
    rows = [measure_mesh(v, body.faces, j) for v, j in zip(verts, joints)]
    if single:
        kept = _MEASURED.setdefault(body, {})
        if len(kept) >= MEASURED_KEPT:
            kept.pop(next(iter(kept)))
        kept[b.tobytes()] = dict(rows[0])
        return rows[0]
    return {k: np.array([r[k] for r in rows]) for k in MEASUREMENTS + MASS}


def format_body(m: dict) -> str:
    """'height 175 cm, chest 110 cm, waist 89 cm, hip 102 cm, arm length 56 cm, leg length 84 cm,
    mass 76 kg, BMI 24.6' for one ``measure`` dict (keys it lacks are left out)."""
    parts = [f"{k.replace('_cm', '').replace('_', ' ')} {float(m[k]):.0f} cm" for k in MEASUREMENTS if k in m]
    if "mass_kg" in m:
        parts.append(f"mass {float(m['mass_kg']):.0f} kg")
    if "bmi" in m:
        parts.append(f"BMI {float(m['bmi']):.1f}")
    return ", ".join(parts)
