"""Body mass from the mesh: closed-mesh volume x a whole-body density; and the body-mass index.

Volume: the divergence theorem on the closed triangle mesh (OpenBody's every edge is shared by
exactly two faces; the SMPL meshes are closed too), V = |sum_f v0 . (v1 x v2)| / 6, exact for the
mesh. Mass = V x ``DENSITY_KG_M3``.

Density: 985 kg/m^3, the whole-body density of a living person with normal lung air that is
commonly quoted (e.g. "The average density of the human body is approximately 985 kg/m3",
biologyinsights.com/what-is-the-density-of-a-human-why-does-it-matter; the same figure on
zaro.info's human-body-properties page, 945 kg/m^3 after a full breath). Anny, OpenBody's source
model, uses 980 kg/m^3 in its anthropometry module (naver/anny, ``anthropometry.py``, Apache-2.0).
Hydrostatic weighing with the lungs emptied gives 1,060-1,070 kg/m^3 (lean tissue ~1,100, fat
~900): the mesh has no lungs to empty, so the with-air figure is the right one for its volume.
One density for everybody: a muscular body is really a little denser, a fat one a little lighter
(a few %), which this does not model.

BMI = mass / height^2 (kg/m^2), height the mesh's top minus its lowest vertex.
"""
from __future__ import annotations

import numpy as np

DENSITY_KG_M3 = 985.0


def mesh_volume(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Volume in m^3 of closed triangle meshes: vertices (V,3) or (B,V,3) metres, faces (F,3) ->
    a float (or (B,) array)."""
    v = np.asarray(vertices, np.float64)
    f = np.asarray(faces)
    a, b, c = v[..., f[:, 0], :], v[..., f[:, 1], :], v[..., f[:, 2], :]
    vol = np.abs(np.einsum("...fi,...fi->...", a, np.cross(b, c))) / 6.0
    return vol


def mass_kg(vertices: np.ndarray, faces: np.ndarray, density: float = DENSITY_KG_M3) -> np.ndarray:
    """Body mass in kg of closed meshes (see ``mesh_volume``) at ``density`` kg/m^3."""
    return mesh_volume(vertices, faces) * float(density)


def bmi(mass: np.ndarray, height_cm: np.ndarray) -> np.ndarray:
    """Body-mass index, kg/m^2."""
    return np.asarray(mass, np.float64) / (np.asarray(height_cm, np.float64) / 100.0) ** 2
