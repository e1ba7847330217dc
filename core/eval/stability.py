"""HUMOS's dynamic stability: centre of mass from per-part volumes, zero-moment point (ZMP) and
base of support (BoS). Metres, Y up, ground y = 0, 20 fps.

**Mass model.** The mesh is segmented into the 24 skinning parts: each triangle goes to the joint
with the largest summed skin weight over its three corners. Each part is closed into a solid:
every seam edge (an edge whose neighbouring triangle belongs to another part, or a hole edge with
no neighbour) gets a cap triangle fanned to the centroid of the vertices of that seam (one seam
per unordered pair of parts, holes of a part share one). Two parts sharing a seam get opposite cap
triangles with the same apex, so they cancel: the part volumes always sum to the volume of the
whole closed mesh. Volume and centroid of a closed, consistently oriented surface come from the
divergence theorem as a fan of signed tetrahedra (origin, a, b, c): V = sum det[a b c] / 6 and
centroid = sum V_i (a + b + c) / 4 / V, origin at the frame's mean vertex for precision (the
result does not depend on it). As HUMOS, density is uniform by default, so
CoM = volume-weighted mean of the part centroids; ``densities`` (24,) can weight the parts.
HUMOS spreads each part's mass uniformly over its vertices instead; the solid centroid used here
does not depend on how densely a region is meshed.

**ZMP.** The point-mass (cart-table) model: with CoM c(t) and its acceleration a(t) by central
finite differences at 20 fps (end frames copy their neighbour, as HUMOS pads its ZMPs),
x_zmp = c_x - c_y a_x / (a_y + g), z_zmp = c_z - c_y a_z / (a_y + g). HUMOS also subtracts the rate
of change of angular momentum about the CoM (per-vertex masses); the point-mass model leaves it
out. Where a_y + g <= 0 (free fall) the ZMP is undefined and the frame is unstable.

**Base of support.** As HUMOS, contact vertices are those less than ``height`` (5 cm) above the
ground that move less than ``max_step`` (2 cm) to the next frame; the BoS is the convex hull of
their XZ projection. A frame is stable when its ZMP lies inside the BoS. As HUMOS, frames without
any contact vertex count as unstable (``no_contact="exclude"`` leaves them out instead), and the
out-of-BoS distance is averaged over the frames with contact whose ZMP lies outside.
"""
from __future__ import annotations

from collections import defaultdict

import numpy as np
import torch

from ..constants import FPS
from ..errors import ShapeMoveError

GRAVITY = 9.81
SUPPORT_HEIGHT = 0.05      # m (HUMOS CONTACT_THRESH)
SUPPORT_STEP = 0.02        # m per frame (HUMOS VELOCITY_THRESH)
_DIRECTIONS = np.stack([np.cos(np.arange(32) * np.pi / 16), np.sin(np.arange(32) * np.pi / 16)], axis=1)


class MassModel:
    """Per-part solids of a closed triangle mesh. faces (F,3) int, skin_weights (V,J)."""

    def __init__(self, faces, skin_weights, densities=None):
        faces = np.asarray(faces, dtype=np.int64)
        w = skin_weights.detach().cpu().numpy() if isinstance(skin_weights, torch.Tensor) else np.asarray(skin_weights)
        if faces.ndim != 2 or faces.shape[1] != 3 or faces.size == 0:
            raise ShapeMoveError(f"faces must be a non-empty (F,3) triangle list, got shape {faces.shape}")
        self.num_vertices, self.num_parts = w.shape
        self.face_part = w[faces].sum(axis=1).argmax(axis=1)
        caps, cap_part, groups = self._seam_caps(faces, self.face_part)
        caps[:, 2] += self.num_vertices           # apex points are appended after the vertices
        # apex of each seam = mean of the seam's vertices, as a sparse (G,V) average
        pairs = sorted({(g, v) for g, verts in enumerate(groups) for v in verts})
        self.apex_group = torch.tensor([p[0] for p in pairs], dtype=torch.long)
        self.apex_vertex = torch.tensor([p[1] for p in pairs], dtype=torch.long)
        self.apex_count = torch.tensor([len(g) for g in groups], dtype=torch.float64)
        self.num_groups = len(groups)
        tris = np.concatenate([faces, caps])
        self.tris = torch.as_tensor(tris, dtype=torch.long)
        self.tri_part = torch.as_tensor(np.concatenate([self.face_part, cap_part]), dtype=torch.long)
        d = np.ones(self.num_parts) if densities is None else np.asarray(densities, dtype=np.float64)
        if d.shape != (self.num_parts,) or (d < 0).any():
            raise ShapeMoveError(f"densities must be {self.num_parts} non-negative values")
        self.densities = torch.as_tensor(d, dtype=torch.float64)

    @staticmethod
    def _seam_caps(faces, face_part):
        """Cap triangles (b, a, apex) for every directed seam edge a->b of a part."""
        directed = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
        part = np.repeat(face_part, 3)
        owners = defaultdict(list)              # undirected edge -> [(occurrence, part)]
        for i, (a, b) in enumerate(directed):
            owners[(min(a, b), max(a, b))].append((i, part[i]))
        group_of, groups, caps, cap_part = {}, [], [], []
        for occ in owners.values():
            parts = [p for _, p in occ]
            for i, p in occ:
                if parts.count(p) > 1:
                    continue                      # interior edge of part p
                other = next((q for q in parts if q != p), -1)
                key = (min(p, other), max(p, other)) if other >= 0 else (p, -1)
                g = group_of.setdefault(key, len(groups))
                if g == len(groups):
                    groups.append(set())
                a, b = directed[i]
                groups[g].update((int(a), int(b)))
                caps.append((b, a, g))
                cap_part.append(p)
        return np.asarray(caps, dtype=np.int64).reshape(-1, 3), np.asarray(cap_part, dtype=np.int64), groups

    def part_volumes(self, vertices) -> tuple[torch.Tensor, torch.Tensor]:
        """(B,V,3) vertices -> part volumes (B,J) in m^3 and part centroids (B,J,3) (NaN if empty).
        Computed in the input's precision (float32: ~1e-5 relative, float64 for exact checks)."""
        v = torch.as_tensor(vertices)
        v = v if v.dtype in (torch.float32, torch.float64) else v.to(torch.float64)
        if v.dim() == 2:
            v = v[None]
        if v.dim() != 3 or v.shape[1:] != (self.num_vertices, 3):
            raise ShapeMoveError(f"vertices must be (B,{self.num_vertices},3), got {tuple(v.shape)}")
        origin = v.mean(dim=1, keepdim=True)
        v = v - origin
        B = v.shape[0]
        apex = v.new_zeros(B, self.num_groups, 3).index_add_(1, self.apex_group, v[:, self.apex_vertex])
        apex = apex / self.apex_count.to(v.dtype)[None, :, None]
        tris = self.tris
        pts = torch.cat([v, apex], dim=1)
        a, b, c = (pts.index_select(1, tris[:, k]) for k in range(3))
        det = (a * torch.linalg.cross(b, c)).sum(-1) / 6.0                     # (B,N)
        vol = v.new_zeros(B, self.num_parts).index_add_(1, self.tri_part, det)
        mom = v.new_zeros(B, self.num_parts, 3).index_add_(1, self.tri_part, det[..., None] * (a + b + c) / 4)
        sign = torch.sign(vol.sum(dim=1, keepdim=True))                      # inward-facing meshes
        sign[sign == 0] = 1
        vol = vol * sign
        centroid = mom * sign[..., None] / vol[..., None] + origin
        centroid[vol.abs() < 1e-12] = float("nan")
        return vol, centroid

    def center_of_mass(self, vertices) -> torch.Tensor:
        """(B,V,3) vertices -> (B,3) CoM = density*volume-weighted mean of the part centroids."""
        vol, cen = self.part_volumes(vertices)
        m = vol * self.densities.to(vol.dtype)
        cen = torch.nan_to_num(cen)
        return (m[..., None] * cen).sum(1) / m.sum(1, keepdim=True)


def zmp(com, fps: float = FPS, g: float = GRAVITY) -> np.ndarray:
    """(T,3) CoM trajectory -> (T,3) ZMP on the ground (y = 0); NaN rows where a_y + g <= 0."""
    c = np.asarray(com.detach().cpu() if isinstance(com, torch.Tensor) else com, dtype=np.float64)
    if c.ndim != 2 or c.shape[1] != 3:
        raise ShapeMoveError(f"com must be (T,3), got shape {c.shape}")
    acc = np.zeros_like(c)
    if len(c) >= 3:
        acc[1:-1] = (c[2:] - 2 * c[1:-1] + c[:-2]) * fps * fps
        acc[0], acc[-1] = acc[1], acc[-2]
    denom = acc[:, 1] + g
    out = np.stack([c[:, 0] - c[:, 1] * acc[:, 0] / denom, np.zeros(len(c)),
                    c[:, 2] - c[:, 1] * acc[:, 2] / denom], axis=1)
    out[denom <= 1e-9] = np.nan
    return out


def support_points(vertices, next_vertices, height: float = SUPPORT_HEIGHT, max_step: float = SUPPORT_STEP) -> list:
    """Contact vertices per frame: (B,V,3) and the same vertices one frame later ->
    list of (N_b,2) XZ points lower than ``height`` that move less than ``max_step``."""
    v = np.asarray(vertices, dtype=np.float64)
    step = np.linalg.norm(np.asarray(next_vertices, dtype=np.float64) - v, axis=-1)
    mask = (v[..., 1] < height) & (step < max_step)
    return [v[b, mask[b]][:, [0, 2]] for b in range(len(v))]


def convex_hull_2d(points) -> np.ndarray:
    """(N,2) points -> (K,2) convex hull, counter-clockwise (Andrew's monotone chain).
    Degenerate inputs give 1 (a point) or 2 (a segment) vertices; empty input gives (0,2)."""
    p = np.round(np.asarray(points, dtype=np.float64).reshape(-1, 2), 6)
    if len(p) > 32:   # Akl-Toussaint: drop points strictly inside the polygon of extreme points
        ext = p[(p @ _DIRECTIONS.T).argmax(axis=0)]
        ext = ext[np.any(ext != np.roll(ext, 1, axis=0), axis=1)]
        if len(ext) >= 3:
            e0, e1 = ext, np.roll(ext, -1, axis=0)
            cross = ((e1 - e0)[None, :, 0] * (p[:, None, 1] - e0[None, :, 1])
                     - (e1 - e0)[None, :, 1] * (p[:, None, 0] - e0[None, :, 0]))
            p = p[(cross <= 1e-12).any(axis=1)]
    p = p[np.lexsort((p[:, 1], p[:, 0]))]                                     # by x, then z
    if len(p):
        p = p[np.r_[True, np.any(p[1:] != p[:-1], axis=1)]]
    if len(p) <= 2:
        return p

    def chain(pts):
        out = []
        for q in pts:
            while len(out) >= 2 and _cross(out[-2], out[-1], q) <= 0:
                out.pop()
            out.append(q)
        return out[:-1]

    hull = np.array(chain(p) + chain(p[::-1]))
    return hull


def _cross(o, a, b) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def distance_outside(hull, point) -> float:
    """Distance (m) from a 2D point to a CCW convex polygon ``hull``; 0 inside or on it, inf if empty."""
    h = np.asarray(hull, dtype=np.float64)
    p = np.asarray(point, dtype=np.float64)
    if len(h) == 0 or not np.isfinite(p).all():
        return float("inf")
    if len(h) == 1:
        return float(np.linalg.norm(p - h[0]))
    start, end = h, np.roll(h, -1, axis=0)
    edge = end - start
    rel = p - start
    if len(h) >= 3 and (edge[:, 0] * rel[:, 1] - edge[:, 1] * rel[:, 0] >= -1e-12).all():
        return 0.0
    t = np.clip((rel * edge).sum(1) / np.maximum((edge * edge).sum(1), 1e-18), 0, 1)
    return float(np.linalg.norm(rel - t[:, None] * edge, axis=1).min())


def dynamic_stability(zmps, hulls, no_contact: str = "unstable", tol: float = 1e-6) -> dict:
    """ZMPs (T,3) and one BoS hull (K,2) per frame -> {"dyn_stable_pct", "zmp_out_cm",
    "n_stability" (frames in the percentage), "n_zmp_out" (frames averaged in zmp_out_cm)}."""
    if no_contact not in ("unstable", "exclude"):
        raise ShapeMoveError(f"no_contact must be 'unstable' or 'exclude', got {no_contact!r}")
    z = np.asarray(zmps, dtype=np.float64)
    if len(z) != len(hulls):
        raise ShapeMoveError(f"need one support hull per frame: {len(z)} ZMPs, {len(hulls)} hulls")
    stable, counted, outside = 0, 0, []
    for p, h in zip(z, hulls):
        if len(h) == 0:
            counted += no_contact == "unstable"
            continue
        counted += 1
        d = distance_outside(h, p[[0, 2]])
        if d <= tol:
            stable += 1
        elif np.isfinite(d):
            outside.append(d)
    return {
        "dyn_stable_pct": 100.0 * stable / counted if counted else 0.0,
        "zmp_out_cm": float(np.mean(outside) * 100) if outside else 0.0,
        "n_stability": counted,
        "n_zmp_out": len(outside),
    }
