"""Fit a body's 10 betas to a motion-capture subject's skeleton (rest joints or bone lengths).

Rest joints are linear in betas, ``J(b) = J0 + Jdirs . b``, so joint positions could be matched by
ridge least squares - but a mocap rest pose is rarely the body's (arms down instead of a T-pose,
another origin), so the robust fit matches BONE LENGTHS of the 22-joint body
(``skeleton.BODY_BONES``, 21 bones), which do not depend on the pose:

    minimise  sum_i w_i (|a_i + B_i b| - L_i)^2  +  reg |b|^2

with Levenberg-Marquardt (Gauss-Newton with damping) in float64, started from zero and, when
positions are given, from the ridge solution on root-relative joints; the better end wins.
``reg`` (m^2 per unit beta^2) = 1e-6 is the MAP weight for ~1 mm bone-length noise under the
N(0,1) beta prior: directions the bone lengths can't see (girth) stay near 0.

That suits a skeleton OF the body. A mocap clip (``fit_betas_to_motion``) is another skeleton:
rig conventions and proportions the 10 betas cannot express leave cm of bone-length error
(OpenBody's first beta carries 98 % of the shape variance, mostly overall size; the other nine
move a joint < 1 cm per unit), and chasing them with reg 1e-6 drives betas to +-20..60 (chest
girths of 3 m). So a clip is fitted with ``MOTION_REG`` (~1.4 cm bone noise) and each bone weighted
by the number of joints it carries (``SUBTREE_WEIGHTS``: a torso bone moves 11-13 joints, a
foot one), which is what the joint error of the retargeted motion counts.

``fit_betas_to_clip`` (the data builder's fit) goes one step further: starting from that fit it
alternates IK and a linear least-squares step on the betas with the IK poses held fixed, so it
also sees where the hips, neck and collars sit (layout, not bone lengths).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ShapeMoveError
from .ik import solve_ik
from .model import NUM_BETAS, BodyModel
from .skeleton import BODY_BONES, JOINT_INDEX, JOINT_NAMES, NUM_BODY_JOINTS, PARENTS

NUM_BONES = len(BODY_BONES)  # 21
DEFAULT_REG = 1e-6
MOTION_REG = 2e-4  # (1.4 cm)^2: betas of real clips stay within the N(0,1) prior (|beta_i| <~ 3)


def _subtree_weights() -> np.ndarray:
    """(21,) joints of the 22-joint body at or below each bone's child, normalised to mean 1."""
    n = np.ones(NUM_BODY_JOINTS)
    for j in range(NUM_BODY_JOINTS - 1, 0, -1):
        n[BODY_BONES[j - 1][0]] += n[j]
    w = n[1:]
    return w / w.mean()


SUBTREE_WEIGHTS = _subtree_weights()


@dataclass
class BetaFit:
    betas: np.ndarray           # (10,) float32
    residual: float             # RMS bone-length error over the fitted bones, metres
    max_error: float            # largest bone-length error over the fitted bones, metres
    target_lengths: np.ndarray  # (21,) metres, NaN for bones not given
    fitted_lengths: np.ndarray  # (21,) bone lengths of the body with ``betas``, metres


def bone_lengths(joints) -> np.ndarray:
    """(..., 22 or 24, 3) joint positions in SMPL order -> (..., 21) lengths of ``BODY_BONES``."""
    j = np.asarray(joints, dtype=np.float64)
    parents, children = zip(*BODY_BONES)
    return np.linalg.norm(j[..., list(children), :] - j[..., list(parents), :], axis=-1)


def _bone_basis(body: BodyModel) -> tuple[np.ndarray, np.ndarray]:
    """Bone vectors of the body as a_i + B_i . b: a (21,3), B (21,3,10), float64."""
    j0 = body.joint_template.detach().cpu().double().numpy()
    jd = body.joint_shapedirs.detach().cpu().double().numpy()
    p, c = (list(x) for x in zip(*BODY_BONES))
    return j0[c] - j0[p], jd[c] - jd[p]


def body_bone_lengths(body: BodyModel, betas=None) -> np.ndarray:
    """(21,) rest-pose bone lengths of ``body`` for ``betas`` (10,) (default zeros), metres."""
    a, B = _bone_basis(body)
    b = np.zeros(NUM_BETAS) if betas is None else np.asarray(betas, dtype=np.float64).reshape(NUM_BETAS)
    return np.linalg.norm(a + B @ b, axis=-1)


def _bone_index(key) -> int:
    """A bone named by its child joint (name or index) or by a (parent, child) pair."""
    if isinstance(key, tuple) and len(key) == 2:
        pair = tuple(JOINT_INDEX.get(k, k) if isinstance(k, str) else k for k in key)
        if pair in BODY_BONES:
            return BODY_BONES.index(pair)
    elif isinstance(key, (str, int, np.integer)):
        child = JOINT_INDEX.get(key, -1) if isinstance(key, str) else int(key)
        if 1 <= child < NUM_BODY_JOINTS:
            return child - 1  # BODY_BONES[i] ends at joint i + 1
    raise ShapeMoveError(f"unknown bone {key!r}: name a bone by its child joint ({', '.join(JOINT_NAMES[1:22])}) "
                         "or as a (parent, child) pair")


def _targets(lengths, weights) -> tuple[np.ndarray, np.ndarray]:
    """Lengths as (21,) array or {bone: length} dict -> (targets with NaN, weights with 0 for NaN)."""
    if isinstance(lengths, dict):
        target = np.full(NUM_BONES, np.nan)
        for key, value in lengths.items():
            target[_bone_index(key)] = float(value)
    else:
        target = np.asarray(lengths, dtype=np.float64).reshape(-1)
        if target.shape != (NUM_BONES,):
            raise ShapeMoveError(f"bone lengths must be {NUM_BONES} values (skeleton.BODY_BONES order) or a dict, "
                                 f"got shape {np.shape(lengths)}")
    w = np.ones(NUM_BONES) if weights is None else np.asarray(weights, dtype=np.float64).reshape(-1)
    if w.shape != (NUM_BONES,) or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ShapeMoveError(f"bone weights must be {NUM_BONES} finite values >= 0")
    known = np.isfinite(target)
    if np.any(target[known] <= 0):
        raise ShapeMoveError("bone lengths must be positive (metres)")
    w = np.where(known, w, 0.0)
    if not np.any(w > 0):
        raise ShapeMoveError("no bone length to fit (all missing, NaN or with weight 0)")
    return target, w


def _levenberg_marquardt(a, B, target, w, reg, b0, iterations=50):
    """Minimise sum w (|a + B b| - target)^2 + reg |b|^2 from b0; returns (b, cost)."""
    t = np.nan_to_num(target)

    def terms(b):
        v = a + B @ b
        L = np.linalg.norm(v, axis=-1)
        r = L - t
        return v, L, r, float(np.sum(w * r * r) + reg * b @ b)

    b = np.asarray(b0, dtype=np.float64).copy()
    v, L, r, cost = terms(b)
    lam = 1e-3
    for _ in range(iterations):
        jac = np.einsum("ic,icb->ib", v / np.maximum(L, 1e-12)[:, None], B)  # (21,10) dL/db
        H = jac.T @ (w[:, None] * jac) + reg * np.eye(len(b))
        g = jac.T @ (w * r) + reg * b
        step = np.linalg.solve(H + lam * np.diag(np.diag(H)), -g)
        nv, nL, nr, ncost = terms(b + step)
        if ncost <= cost:
            b, v, L, r, cost, lam = b + step, nv, nL, nr, ncost, max(lam / 3, 1e-9)
            if np.abs(step).max() < 1e-9:
                break
        else:
            lam *= 4
            if lam > 1e9:
                break
    return b, cost


def _result(body, b, target, w) -> BetaFit:
    fitted = body_bone_lengths(body, b)
    err = np.abs(fitted - target)[w > 0]
    return BetaFit(betas=b.astype(np.float32), residual=float(np.sqrt(np.mean(err ** 2))), max_error=float(err.max()),
                   target_lengths=target, fitted_lengths=fitted)


def fit_betas_to_bone_lengths(body: BodyModel, lengths, weights=None, reg: float = DEFAULT_REG,
                              init=None) -> BetaFit:
    """Betas whose 22-joint rest skeleton has the given bone lengths.

    lengths: (21,) metres in ``skeleton.BODY_BONES`` order (NaN = unknown), or a dict
    {child joint name | (parent, child): metres}; weights (21,) >= 0 per bone; reg >= 0 ridge
    weight on betas (m^2); init (10,) or a list of starting points.
    """
    target, w = _targets(lengths, weights)
    if reg < 0:
        raise ShapeMoveError("reg must be >= 0")
    a, B = _bone_basis(body)
    ratio = np.median(target[w > 0] / np.linalg.norm(a, axis=-1)[w > 0])
    if not 0.25 < ratio < 4:
        raise ShapeMoveError(f"bone lengths are {ratio:.3g} times the body's: give them in metres")
    starts = [np.zeros(NUM_BETAS)] if init is None else [np.asarray(s, dtype=np.float64).reshape(NUM_BETAS)
                                                         for s in (init if isinstance(init, list) else [init])]
    best = min((_levenberg_marquardt(a, B, target, w, reg, s) for s in starts), key=lambda bc: bc[1])
    return _result(body, best[0], target, w)


def fit_betas_to_motion(body: BodyModel, joints, weights=None, reg: float = MOTION_REG) -> BetaFit:
    """Betas of a body that carries a mocap clip: joints (T,22,3) (or (T,24,3)) metres in SMPL order,
    e.g. ``Motion22.joints``. Fits the median bone lengths over the frames with ``SUBTREE_WEIGHTS``
    (or ``weights`` (21,)) and the ``MOTION_REG`` prior, so the betas stay a plausible body.
    """
    x = np.asarray(joints, dtype=np.float64)
    if x.ndim != 3 or x.shape[0] < 1 or x.shape[1] not in (NUM_BODY_JOINTS, 24) or x.shape[2] != 3:
        raise ShapeMoveError(f"motion joints must be (T,22,3) or (T,24,3) in SMPL joint order, got shape {x.shape}")
    ok = np.all(np.isfinite(x[:, :NUM_BODY_JOINTS]), axis=(1, 2))
    if not ok.any():
        raise ShapeMoveError("motion joints contain no finite frame")
    lengths = np.median(bone_lengths(x[ok, :NUM_BODY_JOINTS]), axis=0)
    return fit_betas_to_bone_lengths(body, lengths, SUBTREE_WEIGHTS if weights is None else weights, reg)


def fit_betas_to_positions(body: BodyModel, joints, weights=None, reg: float = DEFAULT_REG) -> np.ndarray:
    """Ridge least squares on root-relative rest joints (only right if the rest POSE matches the body's).

    joints (22 or 24, 3) metres in SMPL order and the body's axes; weights (22,) per joint. -> (10,).
    """
    x = _positions(joints)
    j0 = body.joint_template.detach().cpu().double().numpy()[:NUM_BODY_JOINTS]
    jd = body.joint_shapedirs.detach().cpu().double().numpy()[:NUM_BODY_JOINTS]
    w = np.ones(NUM_BODY_JOINTS) if weights is None else np.asarray(weights, dtype=np.float64).reshape(-1)
    if w.shape != (NUM_BODY_JOINTS,) or np.any(w < 0):
        raise ShapeMoveError(f"joint weights must be {NUM_BODY_JOINTS} values >= 0")
    A = (jd[1:] - jd[:1]).reshape(-1, NUM_BETAS)  # (21*3,10)
    y = ((x[1:] - x[:1]) - (j0[1:] - j0[:1])).reshape(-1)
    sw = np.repeat(w[1:], 3)
    return np.linalg.solve(A.T @ (sw[:, None] * A) + reg * np.eye(NUM_BETAS), A.T @ (sw * y))


def _positions(joints) -> np.ndarray:
    x = np.asarray(joints, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3 or x.shape[0] not in (NUM_BODY_JOINTS, 24):
        raise ShapeMoveError(f"rest joints must be (22,3) or (24,3) in SMPL joint order, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ShapeMoveError("rest joints contain NaN or infinite values")
    return x[:NUM_BODY_JOINTS]


def fit_betas_to_skeleton(body: BodyModel, skeleton, weights=None, reg: float = DEFAULT_REG,
                          match: str = "lengths") -> BetaFit:
    """A mocap subject's skeleton -> betas.

    skeleton: rest joint positions (22,3) / (24,3) metres in SMPL joint order, or a bone-length dict
    (see ``fit_betas_to_bone_lengths``). match="lengths" (default) fits bone lengths, robust to a
    different rest pose; match="positions" is plain ridge on root-relative joints. weights: per bone
    (21,) for "lengths", per joint (22,) for "positions".
    """
    if isinstance(skeleton, dict):
        return fit_betas_to_bone_lengths(body, skeleton, weights, reg)
    if hasattr(skeleton, "detach"):
        skeleton = skeleton.detach().cpu().numpy()
    x = _positions(skeleton)
    if match == "positions":
        b = fit_betas_to_positions(body, x, weights, reg)
        return _result(body, b, bone_lengths(x), np.ones(NUM_BONES))
    if match != "lengths":
        raise ShapeMoveError(f"match must be 'lengths' or 'positions', got {match!r}")
    ridge = fit_betas_to_positions(body, x, None, reg)
    return fit_betas_to_bone_lengths(body, bone_lengths(x), weights, reg, init=[np.zeros(NUM_BETAS), ridge])


CLIP_REG = 1e-4       # the bone-length start (``fit_betas_to_motion``): real clips keep |beta| <~ 2.5
CLIP_POSE_REG = 1e-5  # per frame and joint, m^2 per unit beta^2, in the pose-aware rounds
CLIP_FRAMES = 48     # frames (evenly spread) the clip fit looks at
CLIP_ROUNDS = 3      # IK <-> betas alternations


def _world_rotations(rot: np.ndarray) -> np.ndarray:
    """(F,24,3,3) local rotations -> (F,22,3,3) world rotations of the body joints."""
    G = np.empty((rot.shape[0], NUM_BODY_JOINTS, 3, 3))
    G[:, 0] = rot[:, 0]
    for j in range(1, NUM_BODY_JOINTS):
        G[:, j] = G[:, PARENTS[j]] @ rot[:, j]
    return G


def fit_betas_to_clip(body: BodyModel, joints, reg: float = CLIP_REG, pose_reg: float = CLIP_POSE_REG,
                      frames: int = CLIP_FRAMES, rounds: int = CLIP_ROUNDS, refine_iters: int = 2) -> BetaFit:
    """Betas for retargeting a mocap clip onto ``body`` by IK with the least joint error: the data
    builder's fit. joints (T,22,3) (or (T,24,3)) metres in SMPL order, e.g. ``Motion22.joints``.

    Starts from ``fit_betas_to_motion`` (bone lengths), then alternates ``rounds`` times, on
    ``frames`` evenly spread frames: IK (``ik.solve_ik``) with the current betas, then the betas
    (and per-frame translations) that minimise the squared joint error of THOSE poses - with the
    rotations fixed, forward kinematics is linear in the rest joints, so in the betas - plus
    ``reg`` x frames x 22 x |betas|^2 (a N(0,1) prior at ~1.4 cm joint noise). Unlike bone lengths
    this sees the layout of the pelvis and chest (where hips, neck and collars sit), which is
    what the joint error counts. The IK poses change with the betas, hence the rounds; the
    result with the lowest IK error (bone-length fit included) wins.
    """
    x = np.asarray(joints, dtype=np.float64)
    if pose_reg < 0 or frames < 1 or rounds < 0:
        raise ShapeMoveError("pose_reg must be >= 0, frames >= 1 and rounds >= 0")
    start = fit_betas_to_motion(body, joints, reg=reg)
    ok = np.flatnonzero(np.all(np.isfinite(x[:, :NUM_BODY_JOINTS]), axis=(1, 2)))
    tgt = x[ok[np.unique(np.linspace(0, len(ok) - 1, min(frames, len(ok))).round().astype(int))], :NUM_BODY_JOINTS]
    F = len(tgt)
    j0 = body.joint_template.detach().cpu().double().numpy()[:NUM_BODY_JOINTS]
    jd = body.joint_shapedirs.detach().cpu().double().numpy()[:NUM_BODY_JOINTS]
    par = PARENTS[:NUM_BODY_JOINTS]
    # bone offsets a_k + B_k b (pelvis: its rest position)
    a = j0.copy()
    a[1:] -= j0[par[1:]]
    B = jd.copy()
    B[1:] -= jd[par[1:]]
    # chain[k, i] = 1 when bone i lies on the path from the pelvis to joint k (itself included)
    chain = np.zeros((NUM_BODY_JOINTS, NUM_BODY_JOINTS))
    for k in range(NUM_BODY_JOINTS):
        i = k
        while i >= 0:
            chain[k, i] = 1.0
            i = par[i]

    def ik_error(b):
        rest = body.rest_joints(np.asarray(b, np.float32)[None])[0].double().numpy()
        res = solve_ik(tgt, rest, refine_iters=refine_iters)
        return res, float(res.joint_error.mean())

    best_b = start.betas.astype(np.float64)
    res, best_err = ik_error(best_b)
    b = best_b
    for _ in range(rounds):
        G = _world_rotations(res.rotations.astype(np.float64))
        # the world rotation that carries bone i: its parent's (the pelvis offset is not rotated)
        R = np.concatenate([np.broadcast_to(np.eye(3), (F, 1, 3, 3)), G[:, par[1:]]], 1)   # (F,22,3,3)
        Ra, RB = np.einsum("fiab,ib->fia", R, a), np.einsum("fiab,ibc->fiac", R, B)
        pa = np.einsum("ki,fia->fka", chain, Ra)           # (F,22,3)  FK at betas 0, no translation
        pB = np.einsum("ki,fiac->fkac", chain, RB)         # (F,22,3,10)
        # the per-frame translation is free: centre both sides over the joints
        r = (tgt - pa) - (tgt - pa).mean(1, keepdims=True)
        M = pB - pB.mean(1, keepdims=True)
        M = M.reshape(-1, NUM_BETAS)
        b = np.linalg.solve(M.T @ M + pose_reg * F * NUM_BODY_JOINTS * np.eye(NUM_BETAS), M.T @ r.reshape(-1))
        res, err = ik_error(b)
        if err < best_err:
            best_b, best_err = b, err
    return _result(body, best_b, start.target_lengths, np.where(np.isfinite(start.target_lengths), 1.0, 0.0))
