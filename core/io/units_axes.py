"""Detect a mocap file's length unit and up axis from the skeleton itself, and convert to metres,
Y up (the rotation keeps handedness, so the subject's left stays left).

Unit: the candidate (m, cm, mm, inch) that makes the thigh+shin length closest to an adult's
0.80 m (or, for a rig we cannot map, the per-frame body extent closest to 1.75 m).
Up axis: the signed world axis closest to the median ankles->head direction (or, unmapped, the
axis of largest per-frame extent).
"""
from __future__ import annotations

import numpy as np

from .rig_map import find_rig, mapping_matrix, pose_candidates

UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "inch": 0.0254}
LEG_M = 0.80     # hip->knee->ankle of an adult, metres
EXTENT_M = 1.75  # largest per-frame extent of a standing adult, metres

# rotations taking each signed axis to +Y (proper rotations: no mirroring)
_TO_Y_UP = {
    "Y": np.eye(3),
    "Z": np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], float),    # (x,y,z) -> (x, z, -y)
    "-Z": np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], float),   # (x,y,z) -> (x, -z, y)
    "-Y": np.array([[1, 0, 0], [0, -1, 0], [0, 0, -1]], float),  # 180 deg about X
    "X": np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]], float),    # (x,y,z) -> (-y, x, z)
    "-X": np.array([[0, 1, 0], [-1, 0, 0], [0, 0, 1]], float),   # (x,y,z) -> (y, -x, z)
}


def smpl22_or_none(names, positions, parents=None, rest=None):
    """SMPL22 positions (T,22,3) of a sample of frames, or None for a rig we cannot map (with
    ``parents`` and ``rest`` positions, a rig absent from the tables is matched by its shape)."""
    rig = find_rig(names, parents, None if rest is None else pose_candidates(rest, positions))
    if rig is None:
        return None
    pos = _sample(positions)
    return np.matmul(mapping_matrix(rig, names, pos), pos)


def _sample(positions, n=200):
    """At most n evenly spaced frames (detection needs no more)."""
    step = max(1, len(positions) // n)
    return positions[::step]


def detect_unit(names, positions: np.ndarray, smpl22=None) -> tuple[str, float]:
    """(unit name, metres per unit) for positions (T,J,3) in file units."""
    j = smpl22 if smpl22 is not None else smpl22_or_none(names, positions)
    if j is not None:
        legs = [np.linalg.norm(j[:, a] - j[:, b], axis=-1) for a, b in ((1, 4), (4, 7), (2, 5), (5, 8))]
        size, ref = float(np.median(legs[0] + legs[1]) + np.median(legs[2] + legs[3])) / 2, LEG_M
    else:
        size, ref = float(np.median(np.ptp(_sample(positions), axis=1).max(-1))), EXTENT_M
    if not np.isfinite(size) or size <= 0:
        return "m", 1.0
    unit = min(UNITS, key=lambda u: abs(np.log(size * UNITS[u] / ref)))
    return unit, UNITS[unit]


def _axis_of(v) -> str:
    k = int(np.argmax(np.abs(v)))
    return ("-" if v[k] < 0 else "") + "XYZ"[k]


def _upright(j: np.ndarray) -> np.ndarray:
    """(T,22,3) -> (T,) bool: head above the ankles along one world axis, both legs along it."""
    up = j[:, 15] - 0.5 * (j[:, 7] + j[:, 8])
    n = np.maximum(np.linalg.norm(up, axis=-1), 1e-12)
    ok = np.abs(up).max(-1) > 0.9 * n
    for hip, ankle in ((1, 7), (2, 8)):
        leg = j[:, hip] - j[:, ankle]
        ok &= np.sum(leg * up, -1) > 0.9 * n * np.maximum(np.linalg.norm(leg, axis=-1), 1e-12)
    return ok


def detect_up_axis(names, positions: np.ndarray, rest: np.ndarray | None = None, smpl22=None, parents=None) -> str:
    """'Y', 'Z', '-Y', '-Z', 'X' or '-X': the world axis pointing up in positions (T,J,3).

    The rest skeleton ``rest`` (J,3) decides when it stands upright (ASF and most BVH rigs); else
    the frames where the subject stands upright vote (a clip that lies on the floor still has some);
    else the median ankles->head direction. ``parents`` lets a rig absent from the tables be
    matched by its shape."""
    rig = find_rig(names, parents, None if rest is None else pose_candidates(rest, positions))
    if rig is None:
        ext = np.median(np.ptp(_sample(positions), axis=1), axis=0)
        return "XYZ"[int(np.argmax(ext))] if np.all(np.isfinite(ext)) else "Y"
    if rest is not None:
        r = rest[None]
        jr = np.matmul(mapping_matrix(rig, names, r), r)
        if _upright(jr)[0]:
            return _axis_of(jr[0, 15] - 0.5 * (jr[0, 7] + jr[0, 8]))
    j = smpl22 if smpl22 is not None else smpl22_or_none(names, positions, parents, rest)
    up = j[:, 15] - 0.5 * (j[:, 7] + j[:, 8])
    ok = _upright(j)
    if ok.any():
        u = up[ok]
        k = np.abs(u).argmax(-1)
        votes = k * 2 + (np.take_along_axis(u, k[:, None], -1)[:, 0] < 0)   # (axis, sign) codes
        best = int(np.bincount(votes, minlength=6).argmax())
        return ("-" if best % 2 else "") + "XYZ"[best // 2]
    v = np.median(up, axis=0)
    return _axis_of(v) if np.all(np.isfinite(v)) and np.any(v) else "Y"


def to_y_up(axis: str) -> np.ndarray:
    """(3,3) proper rotation taking ``axis`` to +Y (Z-up rigs facing -Y end up facing +Z)."""
    return _TO_Y_UP[axis].copy()
