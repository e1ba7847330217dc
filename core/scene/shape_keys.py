"""Shape keys of a linear body model: one key per beta with key value = beta.

Key i holds  template + shapedirs[:, :, i]  (a unit step of beta i), so with Blender's relative
shape keys the mesh is  template + sum_i value_i * shapedirs[:, :, i],  the body model's rest
shape for betas = values. Joints are linear in betas too: ``body.body_arrays.rest_joints_for``.
"""
from __future__ import annotations

import numpy as np


def shape_key_coords(v_template, shapedirs) -> np.ndarray:
    """v_template (V,3), shapedirs (V,3,K) -> (K,V,3) absolute coordinates of each key."""
    t = np.asarray(v_template, dtype=np.float64)
    d = np.asarray(shapedirs, dtype=np.float64)
    return t[None] + np.moveaxis(d, -1, 0)
