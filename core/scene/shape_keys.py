"""Shape keys of a linear body model: one key per beta with key value = beta.

Key i holds  template + shapedirs[:, :, i]  (a unit step of beta i), so with Blender's relative
shape keys the mesh is  template + sum_i value_i * shapedirs[:, :, i],  the body model's rest
shape for betas = values. Joints are linear in betas too: J(b) = joint_template + joint_dirs . b.
"""
from __future__ import annotations

import numpy as np


def shape_key_coords(v_template, shapedirs) -> np.ndarray:
    """v_template (V,3), shapedirs (V,3,K) -> (K,V,3) absolute coordinates of each key."""
    t = np.asarray(v_template, dtype=np.float64)
    d = np.asarray(shapedirs, dtype=np.float64)
    return t[None] + np.moveaxis(d, -1, 0)


def rest_joints_for(joint_template, joint_shapedirs, betas) -> np.ndarray:
    """joint_template (J,3), joint_shapedirs (J,3,K), betas (K,) -> (J,3) rest joints."""
    return np.asarray(joint_template, dtype=np.float64) + np.asarray(joint_shapedirs, dtype=np.float64) @ np.asarray(betas, dtype=np.float64)
