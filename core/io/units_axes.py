"""Detect a mocap file's length unit and up axis from the skeleton itself, and convert to metres,
Y up (the rotation keeps handedness, so the subject's left stays left).

Unit: the candidate (m, cm, mm, inch) that makes the thigh+shin length closest to an adult's
0.80 m (or, for a rig we cannot map, the per-frame body extent closest to 1.75 m).
Up axis: the signed world axis closest to the median ankles->head direction (or, unmapped, the
axis of largest per-frame extent).
"""
from __future__ import annotations

import numpy as np

from .rig_map import find_rig, mapping_matrix

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


def _smpl22(names, positions):
    rig = find_rig(names)
    if rig is None:
        return None
    return np.einsum("sj,tjc->tsc", mapping_matrix(rig, names, positions), positions)


def _sample(positions, n=200):
    """At most n evenly spaced frames (detection needs no more)."""
    step = max(1, len(positions) // n)
    return positions[::step]


def detect_unit(names, positions: np.ndarray) -> tuple[str, float]:
    """(unit name, metres per unit) for positions (T,J,3) in file units."""
    pos = _sample(positions)
    j = _smpl22(names, pos)
    if j is not None:
        legs = [np.linalg.norm(j[:, a] - j[:, b], axis=-1) for a, b in ((1, 4), (4, 7), (2, 5), (5, 8))]
        size, ref = float(np.median(legs[0] + legs[1]) + np.median(legs[2] + legs[3])) / 2, LEG_M
    else:
        size, ref = float(np.median(np.ptp(pos, axis=1).max(-1))), EXTENT_M
    if not np.isfinite(size) or size <= 0:
        return "m", 1.0
    unit = min(UNITS, key=lambda u: abs(np.log(size * UNITS[u] / ref)))
    return unit, UNITS[unit]


def detect_up_axis(names, positions: np.ndarray) -> str:
    """'Y', 'Z', '-Y', '-Z', 'X' or '-X': the world axis pointing up in these positions (T,J,3)."""
    pos = _sample(positions)
    j = _smpl22(names, pos)
    if j is not None:
        v = np.median(j[:, 15] - 0.5 * (j[:, 7] + j[:, 8]), axis=0)
        if not np.all(np.isfinite(v)) or not np.any(v):
            return "Y"
        k = int(np.argmax(np.abs(v)))
        return ("-" if v[k] < 0 else "") + "XYZ"[k]
    ext = np.median(np.ptp(pos, axis=1), axis=0)
    return "XYZ"[int(np.argmax(ext))] if np.all(np.isfinite(ext)) else "Y"


def to_y_up(axis: str) -> np.ndarray:
    """(3,3) proper rotation taking ``axis`` to +Y (Z-up rigs facing -Y end up facing +Z)."""
    return _TO_Y_UP[axis].copy()
