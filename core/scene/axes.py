"""Y-up (ShapeMove, SMPL) -> Z-up (Blender) as one clean rotation of +90 degrees about X.

ShapeMove data is Y up, the rest pose faces +Z, the body's left at +X. After the rotation the
body stands along Blender's +Z, faces -Y (so Blender's Front view sees its face) and keeps its
left at +X. The scene builder bakes this rotation into the mesh and armature data, so both
objects keep an identity transform.
"""
from __future__ import annotations

import numpy as np

# (x, y, z)_Y-up -> (x, -z, y)_Z-up
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def points_to_z_up(points) -> np.ndarray:
    """(..., 3) positions or directions in Y-up -> the same in Z-up."""
    return np.asarray(points, dtype=np.float64) @ Y_UP_TO_Z_UP.T


def points_to_y_up(points) -> np.ndarray:
    """Inverse of ``points_to_z_up``."""
    return np.asarray(points, dtype=np.float64) @ Y_UP_TO_Z_UP


def rotations_to_z_up(rotations) -> np.ndarray:
    """(..., 3, 3) rotation matrices acting on Y-up vectors -> the same rotations on Z-up vectors."""
    r = np.asarray(rotations, dtype=np.float64)
    return Y_UP_TO_Z_UP @ r @ Y_UP_TO_Z_UP.T
