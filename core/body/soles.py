"""Where the soles are: the mesh points that touch the floor, for grounding motion on the MESH.

OpenBody's soles sit below its foot joints (rest pose: ankles ~7.7 cm, foot/ball joints ~2.7 cm
above the floor), so putting a foot *joint* on y = 0 sinks the mesh. Two tools:

* ``sole_offsets(body, betas)`` (B,4): rest height of joints 7, 8, 10, 11 (left ankle, right
  ankle, left foot, right foot) above the lowest vertex of their own skin region (heel region for
  the ankles, forefoot for the foot joints). Linear-cost, batched, differentiable in nothing (it
  is a constant per body): the training losses use it to turn joint heights into sole heights.
* ``GroundProbe(body, betas)``: the foot vertices (exact skinning, they have <= 2 weights) and a
  sparse sample of the rest of the mesh (4 largest weights), posed for many frames at a fraction
  of the cost of skinning the whole mesh. ``lowest(rotations, transl)`` gives per frame the lowest
  foot vertex and the lowest point of the (sampled) body.
"""
from __future__ import annotations

import numpy as np
import torch

from ..geometry.torch_ops import forward_kinematics
from .kinematics import skinning_transforms
from .skeleton import FOOT_JOINTS

FOOT_IDS = FOOT_JOINTS   # left ankle, right ankle, left foot, right foot (SMPL order)
BODY_STRIDE = 24            # every n-th non-foot vertex in the probe (catches knees, hands, seat)
SOLE_HEIGHT = 0.03          # foot vertices up to this rest height are probed (sole, heel, toe tips)
SOLE_STRIDE = 1             # every n-th of them (2 already misses the lowest point by up to 1.3 mm)
TOP_WEIGHTS = 4


def _labels(body) -> np.ndarray:
    return body.skin_weights.argmax(axis=1)


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
    """Posed positions of the sole vertices (+ a sample of the body) for one body shape."""

    def __init__(self, body, betas=None, body_stride: int = BODY_STRIDE):
        b = body._betas(betas)[:1]
        lab = _labels(body)
        low = (body.v_template[:, 1] + body.shapedirs[:, 1] @ b[0]).numpy() < SOLE_HEIGHT
        feet = np.flatnonzero(np.isin(lab, FOOT_IDS) & low)[::SOLE_STRIDE]
        others = np.flatnonzero(~np.isin(lab, FOOT_IDS))[::body_stride]
        ids = np.concatenate([feet, others])
        self.num_feet = len(feet)
        self.foot_side = np.isin(lab[feet], [8, 11]).astype(np.int64)  # 0 left, 1 right
        w = torch.as_tensor(body.skin_weights[ids], dtype=torch.float64)
        top = torch.topk(w, TOP_WEIGHTS, dim=1)
        self.w_idx = top.indices                                          # (n,k)
        self.w = top.values / top.values.sum(1, keepdim=True)
        self.dense_w = torch.zeros(w.shape[1], len(ids), dtype=torch.float64)    # (24,n) of the top weights
        self.dense_w.scatter_(0, self.w_idx.T, self.w.T)
        with torch.no_grad():
            t = torch.as_tensor(ids)
            self.rest_v = (body.v_template[t] + torch.einsum("vcb,b->vc", body.shapedirs[t], b[0])).double()
            self.rest_j = body.rest_joints(b)[0].double()
        self.parents = body.parents
        v1 = torch.cat([self.rest_v, torch.ones(len(ids), 1, dtype=torch.float64)], 1)     # (n,4)
        self.y_map = (self.dense_w[:, None, :] * v1.T[None]).reshape(-1, len(ids)).float()  # (24*4,n)
        self.sole_offsets = sole_offsets(body, b)[0].double().numpy()

    def vertices(self, rotations, transl) -> torch.Tensor:
        """rotations (T,24,3,3) local, transl (T,3) -> (T,n,3) probe points (feet first)."""
        rot = torch.as_tensor(np.asarray(rotations), dtype=torch.float64)
        tr = torch.as_tensor(np.asarray(transl), dtype=torch.float64)
        T = rot.shape[0]
        rest = self.rest_j[None].expand(T, -1, -1)
        posed, world = forward_kinematics(rot, rest, self.parents)
        A = skinning_transforms(world, posed, rest)[..., :3, :]                 # (T,24,3,4)
        M = (A[:, self.w_idx] * self.w[None, :, :, None, None]).sum(2)      # (T,n,3,4)
        v = (M[..., :3] @ self.rest_v[None, :, :, None]).squeeze(-1) + M[..., 3]
        return v + tr[:, None]

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

    def lowest(self, rotations, transl) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per frame: lowest foot vertex of each foot (T,2), lowest foot vertex (T,), lowest probe
        point of the whole body (T,), metres."""
        v = self.heights(rotations, transl)
        f = v[:, :self.num_feet]
        per_foot = np.stack([f[:, self.foot_side == s].min(1) for s in (0, 1)], axis=1)
        return per_foot, f.min(1), v.min(1)
