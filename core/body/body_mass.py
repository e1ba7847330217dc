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

For a body whose vertices are linear in its betas (v = v0 + S b: OpenBody, the SMPL family's rest
mesh) the volume is a cubic polynomial in the betas; ``VolumePolynomial`` holds its coefficients
(computed once, exactly, from the faces) so a fit evaluates a mass in microseconds.
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


def cubic_in_betas(betas, c, l, q, k):
    """c + l.b + b'Qb + K[b,b,b] for (B, n) torch betas and torch coefficients (``VolumePolynomial``'s,
    as given: x density / 6 they give a mass in kg) -> (B,), differentiable."""
    import torch

    return (c + betas @ l + torch.einsum("bp,pq,bq->b", betas, q, betas)
            + torch.einsum("bp,bq,br,pqr->b", betas, betas, betas, k))


def _cross_all(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Cross products over axis 1 of (F,3,...) arrays, broadcast over the trailing axes."""
    return np.stack([x[:, 1] * y[:, 2] - x[:, 2] * y[:, 1], x[:, 2] * y[:, 0] - x[:, 0] * y[:, 2],
                     x[:, 0] * y[:, 1] - x[:, 1] * y[:, 0]], 1)


class VolumePolynomial:
    """The signed volume of a mesh with vertices v0 (V,3) + S (V,3,n) @ b as an exact cubic in b:
    6 V(b) = c + l.b + b'Qb + K[b,b,b], from the triple product's multilinear expansion per face."""

    def __init__(self, v0: np.ndarray, dirs: np.ndarray, faces: np.ndarray):
        v0, dirs, f = np.asarray(v0, np.float64), np.asarray(dirs, np.float64), np.asarray(faces)
        a0, b0, c0 = v0[f[:, 0]], v0[f[:, 1]], v0[f[:, 2]]                 # (F,3)
        A, B, C = dirs[f[:, 0]], dirs[f[:, 1]], dirs[f[:, 2]]              # (F,3,n)
        bc = _cross_all(B[:, :, :, None], C[:, :, None, :])               # (F,3,n,n) B_q x C_r
        self.k = np.einsum("fip,fiqr->pqr", A, bc)
        bc0 = _cross_all(B, c0[:, :, None])                               # B_q x c0
        b0c = _cross_all(b0[:, :, None], C)                               # b0 x C_q
        self.q = np.einsum("fip,fiq->pq", A, bc0) + np.einsum("fip,fiq->pq", A, b0c) + np.einsum("fi,fipq->pq", a0, bc)
        self.l = (np.einsum("fip,fi->p", A, np.cross(b0, c0)) + np.einsum("fi,fip->p", a0, bc0)
                  + np.einsum("fi,fip->p", a0, b0c))
        self.c = float(np.einsum("fi,fi->", a0, np.cross(b0, c0)))

    def __call__(self, betas: np.ndarray) -> np.ndarray:
        """(B,n) betas -> (B,) volume in m^3."""
        b = np.asarray(betas, np.float64).reshape(-1, len(self.l))
        six = (self.c + b @ self.l + np.einsum("bp,pq,bq->b", b, self.q, b)
               + np.einsum("bp,bq,br,pqr->b", b, b, b, self.k, optimize=True))
        return np.abs(six) / 6.0
