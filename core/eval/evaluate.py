"""All per-clip metrics of one motion performed by one body (see physics, bones, stability).

The body mesh is posed in chunks of frames (bounded memory); each chunk is posed with one extra
frame on either side so that per-vertex steps to the next frame are available everywhere.
"""
from __future__ import annotations

import weakref

import numpy as np
import torch

from ..constants import FPS
from ..errors import ShapeMoveError
from . import bones, physics, stability

CHUNK = 64
_MASS_MODELS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
METRIC_KEYS = ("penetrate_cm", "float_cm", "skate_pct", "bone_var_mm", "bone_err_mm", "dyn_stable_pct", "zmp_out_cm",
               "penetrate_all_cm", "float_all_cm", "skate_joints_pct")


def _betas(betas) -> torch.Tensor:
    b = torch.zeros(10) if betas is None else torch.as_tensor(np.asarray(betas), dtype=torch.float32).reshape(-1)
    if b.shape != (10,) or not torch.isfinite(b).all():
        raise ShapeMoveError(f"betas must be 10 finite values, got shape {tuple(b.shape)}")
    return b[None]


def _motion(rotations, transl) -> tuple[torch.Tensor, torch.Tensor]:
    r = torch.as_tensor(np.asarray(rotations), dtype=torch.float32)
    if r.dim() != 4 or r.shape[1:] != (24, 3, 3):
        raise ShapeMoveError(f"rotations must be (T,24,3,3) local rotation matrices, got shape {tuple(r.shape)}")
    T = r.shape[0]
    t = torch.zeros(T, 3) if transl is None else torch.as_tensor(np.asarray(transl), dtype=torch.float32)
    if t.shape != (T, 3):
        raise ShapeMoveError(f"transl must be (T,3) with T={T}, got shape {tuple(t.shape)}")
    if T == 0 or not (torch.isfinite(r).all() and torch.isfinite(t).all()):
        raise ShapeMoveError("the motion is empty or contains NaN/infinite values")
    return r, t


def mesh_motion(body, betas, rotations, transl, chunk: int = CHUNK, mass: stability.MassModel | None = None) -> dict:
    """Pose the mesh chunk by chunk and keep only what the metrics need:
    lowest (T,), feet {side: (T,P,3)}, joints (T,24,3), com (T,3), hulls [T x (K,2)]."""
    b = _betas(betas)
    rot, tr = _motion(rotations, transl)
    T = rot.shape[0]
    if mass is None:
        mass = _MASS_MODELS.get(body)
        if mass is None:
            mass = _MASS_MODELS[body] = stability.MassModel(body.faces, body.skin_weights)
    feet_ids = physics.foot_vertex_ids(body.skin_weights)
    lowest, joints, com, hulls = [], [], [], []
    feet = {side: [] for side in feet_ids}
    with torch.no_grad():
        for s in range(0, T, chunk):
            e = min(s + chunk, T)
            lo, hi = max(s - 1, 0), min(e + 1, T)
            out = body(b, rot[lo:hi], tr[lo:hi])
            v = out.vertices.double()
            inner = v[s - lo:s - lo + (e - s)]
            lowest.append(inner[..., 1].min(dim=1).values)
            joints.append(out.joints[s - lo:s - lo + (e - s)].double())
            for side, ids in feet_ids.items():
                feet[side].append(inner[:, ids])
            com.append(mass.center_of_mass(out.vertices[s - lo:s - lo + (e - s)]).double())
            # step of each vertex to the next frame (the last frame uses the step from the previous)
            vn = v.numpy()
            idx = np.arange(s, e) - lo
            nxt = np.where(idx + lo + 1 < T, idx + 1, idx - 1)
            if T == 1:
                nxt = idx
            hulls += [stability.convex_hull_2d(p) for p in stability.support_points(vn[idx], vn[nxt])]
    return {
        "lowest": torch.cat(lowest).numpy(),
        "feet": {side: torch.cat(x).numpy() for side, x in feet.items()},
        "joints": torch.cat(joints).numpy(),
        "com": torch.cat(com).numpy(),
        "hulls": hulls,
    }


def evaluate_motion(body, betas, rotations, transl, joints=None, target_betas=None, fps: float = FPS,
                    no_contact: str = "unstable", skate_params: dict | None = None) -> dict:
    """Metrics of one clip performed by ``body`` with shape ``betas``.

    rotations (T,24,3,3) local rotations, transl (T,3) m, 20 fps. ``joints`` (T,>=22,3): the
    motion's own joint positions for the bone metrics (e.g. decoded from features); defaults to
    the posed body's joints. ``target_betas``: the body the bone lengths should match (defaults to
    ``betas``). ``skate_params``: keyword arguments of ``physics.skate`` (default GMD's setting);
    ``no_contact``: see ``stability.dynamic_stability``. Returns the ``METRIC_KEYS`` plus the
    frame counts used by ``report.aggregate``.
    """
    m = mesh_motion(body, betas, rotations, transl)
    T = len(m["lowest"])
    pen = physics.penetrate(m["lowest"])
    flo = physics.floating(m["lowest"])
    sk = physics.skate(list(m["feet"].values()), **(skate_params or {}))
    j = m["joints"][:, :22] if joints is None else bones._joints(joints)
    if len(j) != T:
        raise ShapeMoveError(f"joints have {len(j)} frames but the motion has {T}")
    target = bones.target_bone_lengths(body, _betas(betas if target_betas is None else target_betas))
    stab = stability.dynamic_stability(stability.zmp(m["com"], fps=fps), m["hulls"], no_contact=no_contact)
    return {
        "penetrate_cm": pen.value, "float_cm": flo.value, "skate_pct": sk.value,
        "penetrate_all_cm": physics.penetrate_all(m["lowest"]).value,
        "float_all_cm": physics.floating_all(m["lowest"]).value,
        "skate_joints_pct": physics.skate_from_joints(m["joints"][:, :22]).value,  # GMD: the foot joints
        "bone_var_mm": bones.bone_length_variance_mm(j),
        "bone_err_mm": bones.bone_length_error_mm(j, target),
        "dyn_stable_pct": stab["dyn_stable_pct"], "zmp_out_cm": stab["zmp_out_cm"],
        "n_frames": T, "n_penetrate": pen.count, "n_float": flo.count, "n_skate": sk.count,
        "n_stability": stab["n_stability"], "n_zmp_out": stab["n_zmp_out"],
    }


def evaluate_joints(joints, target_lengths=None, sole_offsets=None) -> dict:
    """Joint-only fallback (no mesh): penetrate/float from the ankle and foot joints (minus
    ``sole_offsets``), GMD skating on the foot joints, bone metrics; no dynamic stability (NaN)."""
    j = bones._joints(joints)
    low = physics.lowest_from_joints(j, sole_offsets)
    pen, flo, sk = physics.penetrate(low), physics.floating(low), physics.skate_from_joints(j)
    return {
        "penetrate_cm": pen.value, "float_cm": flo.value, "skate_pct": sk.value,
        "penetrate_all_cm": physics.penetrate_all(low).value, "float_all_cm": physics.floating_all(low).value,
        "skate_joints_pct": sk.value,
        "bone_var_mm": bones.bone_length_variance_mm(j),
        "bone_err_mm": float("nan") if target_lengths is None else bones.bone_length_error_mm(j, target_lengths),
        "dyn_stable_pct": float("nan"), "zmp_out_cm": float("nan"),
        "n_frames": len(j), "n_penetrate": pen.count, "n_float": flo.count, "n_skate": sk.count,
        "n_stability": 0, "n_zmp_out": 0,
    }
