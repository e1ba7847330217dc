"""Write small synthetic SMPL / SMPL-H / SMPL-X model files with the real keys and conventions.

The body is a crude humanoid: an 8-vertex box around every joint of a real-looking SMPL joint
layout (metres, Y up, facing +Z, left at +X) and one around the middle of every bone. Each
joint's J_regressor row averages its own box, so the template joints are exactly the layout.
Shape directions move whole limbs coherently (betas change bone lengths), plus a girth term;
posedirs are small random numbers. Files: ``.npz`` (dense regressor) or a protocol-2 ``.pkl``
with a scipy.sparse regressor and, optionally, shapedirs pickled as a ``chumpy.ch.Ch`` (as in the
official SMPL files) - written without chumpy by a stand-in class with chumpy's pickled layout.
"""
from __future__ import annotations

import pickle
import sys
import types
from pathlib import Path

import numpy as np
import scipy.sparse

SMPL_JOINTS = np.array([
    [0.000, -0.223, 0.028], [0.070, -0.314, 0.024], [-0.068, -0.314, 0.022], [-0.003, -0.109, -0.002],
    [0.103, -0.676, 0.016], [-0.105, -0.680, 0.016], [0.005, 0.025, 0.025], [0.087, -1.082, -0.013],
    [-0.088, -1.090, -0.017], [0.001, 0.078, 0.028], [0.120, -1.145, 0.122], [-0.119, -1.153, 0.121],
    [-0.001, 0.290, -0.012], [0.082, 0.193, -0.005], [-0.079, 0.191, -0.009], [0.005, 0.390, 0.041],
    [0.172, 0.229, -0.019], [-0.170, 0.226, -0.015], [0.430, 0.213, -0.039], [-0.431, 0.211, -0.040],
    [0.685, 0.222, -0.042], [-0.689, 0.219, -0.045], [0.773, 0.213, -0.053], [-0.776, 0.210, -0.056],
])
SMPL_PARENTS = [-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 20, 21]
# finger order of SMPL-H / SMPL-X: index, middle, pinky, ring, thumb (3 joints each)
FINGER_Z = [0.03, 0.01, -0.03, -0.01]
SMALL_VERTEX_IDS = {k: i for i, k in enumerate(
    ["nose", "reye", "leye", "rear", "lear", "LBigToe", "LSmallToe", "LHeel", "RBigToe", "RSmallToe", "RHeel"]
    + [s + f for s in "lr" for f in ("thumb", "index", "middle", "ring", "pinky")])}
"""vertex_ids for smplx.SMPL/SMPLH on these small meshes (smplx's defaults index 6890 vertices)."""


def _hand(wrist: np.ndarray, side: float, wrist_index: int, first: int):
    """15 finger joints for one hand (side +1 left, -1 right) -> positions (15,3), parents (15,)."""
    pos, par = [], []
    for f in range(5):
        if f < 4:
            start, step = wrist + [side * 0.09, 0.0, FINGER_Z[f]], np.array([side * 0.03, 0.0, 0.0])
        else:
            start, step = wrist + [side * 0.03, -0.01, 0.04], np.array([side * 0.02, 0.0, 0.02])
        for k in range(3):
            pos.append(start + k * step)
            par.append(wrist_index if k == 0 else first + 3 * f + k - 1)
    return np.array(pos), par


def skeleton(family: str = "smpl") -> tuple[np.ndarray, list[int]]:
    """Joint layout (J,3) and parents (J,) of the family (24 / 52 / 55 joints)."""
    if family == "smpl":
        return SMPL_JOINTS.copy(), list(SMPL_PARENTS)
    pos, par = [SMPL_JOINTS[:22]], SMPL_PARENTS[:22]
    if family == "smplx":  # jaw, left eye, right eye
        head = SMPL_JOINTS[15]
        pos.append(head + np.array([[0.0, -0.03, 0.04], [0.03, 0.03, 0.08], [-0.03, 0.03, 0.08]]))
        par = par + [15, 15, 15]
    elif family != "smplh":
        raise ValueError(family)
    for side, wrist in ((1.0, 20), (-1.0, 21)):
        first = len(par)
        p, q = _hand(SMPL_JOINTS[wrist], side, wrist, first)
        pos.append(p)
        par = par + q
    return np.concatenate(pos), par


def synthetic_arrays(family: str = "smpl", num_betas: int = 16, seed: int = 0) -> dict:
    """The model arrays, keyed and shaped as in the official files."""
    rng = np.random.default_rng(seed)
    joints, parents = skeleton(family)
    J = len(parents)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    # joint displacement per beta: child moves with its parent plus its own offset
    own = rng.normal(0.0, 0.012, size=(J, 3, num_betas))
    own[..., 0] = 0.06 * (joints - np.array([joints[p] if p >= 0 else joints[0] for p in parents]))  # stature
    disp = np.zeros_like(own)
    for j, p in enumerate(parents):
        disp[j] = own[j] + (disp[p] if p >= 0 else 0.0)
    girth = rng.normal(0.0, 0.15, size=num_betas)

    verts, sdirs, weights, faces, jreg_rows = [], [], [], [], []
    tri = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                    [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])

    def box(centre, half, d, w):
        start = sum(len(v) for v in verts)
        offs = corners * half
        verts.append(centre + offs)
        sdirs.append(d[None] + offs[..., None] * girth)
        weights.append(np.repeat(w[None], 8, 0))
        faces.append(tri + start)
        return np.arange(start, start + 8)

    for j, p in enumerate(parents):
        w = np.zeros(J)
        if p < 0:
            w[j] = 1.0
        else:
            w[j], w[p] = 0.6, 0.4
        jreg_rows.append(box(joints[j], 0.04 if j < 22 else 0.012, disp[j], w))
    for j, p in enumerate(parents[1:], start=1):
        w = np.zeros(J)
        w[p], w[j] = 0.7, 0.3
        box((joints[j] + joints[p]) / 2, 0.03 if j < 22 else 0.008, (disp[j] + disp[p]) / 2, w)

    v = np.concatenate(verts)
    jreg = np.zeros((J, len(v)))
    for j, idx in enumerate(jreg_rows):
        jreg[j, idx] = 1.0 / 8
    kintree = np.array([[2**32 - 1 if p < 0 else p for p in parents], list(range(J))], dtype=np.int64)
    out = {
        "v_template": v, "shapedirs": np.concatenate(sdirs),
        "posedirs": rng.normal(0.0, 1e-3, size=(len(v), 3, 9 * (J - 1))),
        "J_regressor": jreg, "weights": np.concatenate(weights), "kintree_table": kintree,
        "f": np.concatenate(faces).astype(np.uint32),
    }
    if family != "smpl":  # hand PCA as in SMPL-H / SMPL-X files (identity: PCA = axis-angle)
        for s in "lr":
            out[f"hands_components{s}"] = np.eye(45)
            out[f"hands_mean{s}"] = rng.normal(0.0, 0.1, size=45)
    return out


class _FakeCh:
    """Pickles like ``chumpy.ch.Ch``: class chumpy.ch.Ch, state = its __dict__ with the value in x."""

    def __init__(self, x):
        self.x = x
        self._dirty_vars = set()

    def __reduce_ex__(self, protocol):
        import copyreg

        return copyreg.__newobj__, (type(self),), dict(self.__dict__)


def write_model(path: str | Path, family: str = "smpl", chumpy: bool = False, seed: int = 0,
                num_betas: int = 16, drop: tuple = (), **replace) -> dict:
    """Write a synthetic model to ``path`` (.npz or .pkl); ``drop`` keys or ``replace`` arrays to break it.

    Returns the arrays written (dense).
    """
    path = Path(path)
    arrays = synthetic_arrays(family, num_betas, seed)
    arrays.update(replace)
    for k in drop:
        arrays.pop(k)
    if path.suffix == ".npz":
        np.savez(path, **arrays)
        return arrays
    data = dict(arrays)
    if "J_regressor" in data:
        data["J_regressor"] = scipy.sparse.csc_matrix(data["J_regressor"])
    if not chumpy:
        with open(path, "wb") as fh:
            pickle.dump(data, fh, protocol=2)
        return arrays
    # make pickle record the class as chumpy.ch.Ch without chumpy being installed
    saved = {k: sys.modules.get(k) for k in ("chumpy", "chumpy.ch")}
    mod, sub = types.ModuleType("chumpy"), types.ModuleType("chumpy.ch")
    cls = type("Ch", (_FakeCh,), {"__module__": "chumpy.ch", "__qualname__": "Ch"})
    sub.Ch, mod.ch = cls, sub
    sys.modules.update({"chumpy": mod, "chumpy.ch": sub})
    try:
        data["shapedirs"] = cls(data["shapedirs"])
        with open(path, "wb") as fh:
            pickle.dump(data, fh, protocol=2)
    finally:
        for k, m in saved.items():
            if m is None:
                sys.modules.pop(k, None)
            else:
                sys.modules[k] = m
    return arrays
