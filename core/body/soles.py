"""Where the soles are: the mesh points that touch the floor, for grounding motion on the MESH.

OpenBody's soles sit below its foot joints (rest pose: ankles ~7.7 cm, foot/ball joints ~2.7 cm
above the floor), so putting a foot *joint* on y = 0 sinks the mesh. Two tools:

* ``sole_offsets(body, betas)`` (B,4): rest height of joints 7, 8, 10, 11 (left ankle, right
  ankle, left foot, right foot) above the lowest vertex of their own skin region (heel region for
  the ankles, forefoot for the foot joints). Linear-cost, batched, differentiable in nothing (it
  is a constant per body): the training losses use it to turn joint heights into sole heights.
* ``GroundProbe(body, betas)``: the vertices that can ever be the lowest point of the mesh
  (``candidate_vertices``: the extreme points of every rigidly skinned part and all blended
  vertices, ``sole_height.sole_vertices`` over the whole body; about half the mesh, chosen
  once per body model), posed with their full skin weights for many frames at once: only the
  vertical row of each skinning transform is needed, one (T,96) x (96,n) product.
  ``lowest(rotations, transl)`` gives per frame the lowest vertex of each foot, of the feet and of
  the whole body (a kneeling shin, a hand on the floor, a lying back included).
"""
from __future__ import annotations

import numpy as np
import torch

from ..geometry.torch_ops import forward_kinematics
from .kinematics import WINDOW, skinning_transforms
from .skeleton import FOOT_JOINTS
from .sole_height import sole_vertices

FOOT_IDS = FOOT_JOINTS   # left ankle, right ankle, left foot, right foot (SMPL order)


def _labels(body) -> np.ndarray:
    return body.skin_weights.argmax(axis=1)


def candidate_vertices(body) -> np.ndarray:
    """Indices of the vertices that can be the lowest point of ``body``'s mesh in some pose:
    ``sole_height.sole_vertices`` with no height band, on the mean shape (a shape change
    moves an extreme point by a vertex at most: sub-mm). Computed once per body instance."""
    ids = getattr(body, "_ground_candidates", None)
    if ids is None:
        ids = body._ground_candidates = sole_vertices(body.v_template.numpy(), body.skin_weights, 1, band=np.inf)
    return ids


def sole_offsets(body, betas=None) -> torch.Tensor:
    """(B,4) rest height (m) of joints 7, 8, 10, 11 above the lowest vertex skinned mostly to
    that joint, for betas (B,10) or (10,) (None = the mean body)."""
    b = body._betas(betas)
    regions = getattr(body, "_sole_regions", None)
    if regions is None:  # vertex ids of each joint's skin region, once per body instance
        lab = _labels(body)
        regions = body._sole_regions = [torch.as_tensor(np.flatnonzero(lab == j)) for j in FOOT_IDS]
    with torch.no_grad():
        joints_y = body.rest_joints(b)[:, FOOT_IDS, 1]
        out = []
        for k, ids in enumerate(regions):
            y = body.v_template[ids, 1][None] + b @ body.shapedirs[ids, 1].T      # (B,n)
            out.append(joints_y[:, k] - y.min(dim=1).values)
        return torch.stack(out, dim=1)


class GroundProbe:
    """Heights of the mesh's candidate lowest vertices (feet first) for one body shape, any pose."""

    def __init__(self, body, betas=None):
        b = body._betas(betas)[:1]
        lab = _labels(body)
        cand = candidate_vertices(body)
        is_foot = np.isin(lab[cand], FOOT_IDS)
        feet, others = cand[is_foot], cand[~is_foot]
        ids = np.concatenate([feet, others])
        self.num_feet = len(feet)
        self.foot_side = np.isin(lab[feet], [8, 11]).astype(np.int64)  # 0 left, 1 right
        w = torch.as_tensor(body.skin_weights[ids], dtype=torch.float64)
        self.dense_w = (w / w.sum(1, keepdim=True).clamp_min(1e-12)).T.contiguous()  # (24,n)
        with torch.no_grad():
            t = torch.as_tensor(ids)
            self.rest_v = (body.v_template[t] + torch.einsum("vcb,b->vc", body.shapedirs[t], b[0])).double()
            self.rest_j = body.rest_joints(b)[0].double()
        self.parents = body.parents
        v1 = torch.cat([self.rest_v, torch.ones(len(ids), 1, dtype=torch.float64)], 1)     # (n,4)
        self.y_map = (self.dense_w[:, None, :] * v1.T[None]).reshape(-1, len(ids)).float()  # (24*4,n)
        self.sole_offsets = sole_offsets(body, b)[0].double().numpy()

    def heights(self, rotations, transl) -> np.ndarray:
        """(T,n) heights (y, m) of the probe points (feet first): only the y row of each skinning
        transform is needed, (T,24,4) x (4,n), then blended with the dense skin weights."""
        rot = torch.as_tensor(np.asarray(rotations), dtype=torch.float64)
        rest = self.rest_j[None].expand(rot.shape[0], -1, -1)
        posed, world = forward_kinematics(rot, rest, self.parents)
        ay = skinning_transforms(world, posed, rest)[..., 1, :]                  # (T,24,4)
        # y[t,n] = sum_j w[j,n] (ay[t,j,:3] . v[n] + ay[t,j,3]): one (T,96) x (96,n) product
        y = ay.reshape(len(ay), -1).float() @ self.y_map
        return y.double().numpy() + np.asarray(transl, dtype=np.float64)[:, 1:2]

    def lowest(self, rotations, transl, window: int = WINDOW) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per frame: lowest foot vertex of each foot (T,2), lowest foot vertex (T,), lowest probe
        point of the whole body (T,), metres. ``window`` frames at a time (``heights`` is (T,n):
        thousands of points per frame), so memory does not grow with the take's length."""
        rotations, transl = np.asarray(rotations), np.asarray(transl)
        per_foot, feet, body = [], [], []
        for s in range(0, len(rotations), window):
            v = self.heights(rotations[s:s + window], transl[s:s + window])
            f = v[:, :self.num_feet]
            per_foot.append(np.stack([f[:, self.foot_side == k].min(1) for k in (0, 1)], axis=1))
            feet.append(f.min(1))
            body.append(v.min(1))
        if not per_foot:
            return np.zeros((0, 2)), np.zeros(0), np.zeros(0)
        return np.concatenate(per_foot), np.concatenate(feet), np.concatenate(body)
