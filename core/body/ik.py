"""Inverse kinematics: world joint positions -> SMPL local rotations + root translation.

``solve_ik`` is analytic and batched over frames (a Python loop over 13 groups of joints, e.g. both
knees as one batch of 2T frames):

* the root gets a rigid fit (rotation + translation) of the pelvis, hips and spine1; spine3 a
  Kabsch fit of its three child bones;
* spine1/spine2 align their bone and take a left-right axis blended between the pelvis and the
  chest, so a torso twist is spread along the spine;
* hips and shoulders place the knee/elbow (straight at its target, or the two-bone solution that
  also lands the ankle/wrist, whichever misses less) and choose the twist so that the knee/elbow
  bends about a fixed hinge axis (knees about +X, elbows about -/+Y in the rest pose): limbs bend
  consistently and never flip; the knee/elbow is then a pure hinge rotation;
* every other joint with a child takes the minimal rotation (swing) from its parent's frame;
  the leaves of the 22-joint body (head, feet, wrists) and the hands keep the identity.

Each bone is aimed from where forward kinematics actually put its parent, so a small miss does
not accumulate down the chain; a big miss (a body with other proportions) is carried along
instead of folding the next bone (``max_turn_deg``). A few damped Gauss-Newton steps per frame
(``refine``: closed-form Jacobian, one small Cholesky solve per frame, batched) then spread what is
left over the whole chain, letting each bone turn up to ``free_turn_deg`` away from the target
bone's direction at no cost (beyond that a penalty), so a body with other proportions than the
mocap's reaches its joints without folding a chain.

Positions: metres, Y up. Local rotations as in ``kinematics.forward_kinematics``:
``forward_kinematics(rotations, rest_joints) + transl`` reproduces the joints.
``ik_lbfgs_baseline`` is the SMPLify-style optimisation from identity rotations used by the bench.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import torch

from ..errors import ShapeMoveError
from ..geometry.torch_ops import (axis_angle_to_matrix, forward_kinematics, forward_kinematics_offsets, orthonormal_frame,
                                  rotation_between)
from ..torch_threads import one_torch_thread
from .skeleton import NUM_BODY_JOINTS, NUM_JOINTS, PARENTS

# (limb root, hinge joint, end joint, hinge axis in the rest pose; positive angle = flexion)
LIMBS = [
    (1, 4, 7, (1.0, 0.0, 0.0)),     # left hip, knee, ankle: shin swings back (-Z)
    (2, 5, 8, (1.0, 0.0, 0.0)),     # right leg
    (16, 18, 20, (0.0, -1.0, 0.0)),  # left shoulder, elbow, wrist: forearm swings forward (+Z)
    (17, 19, 21, (0.0, 1.0, 0.0)),   # right arm
]
END_JOINTS = [7, 8, 10, 11, 20, 21]  # ankles, feet, wrists
ROOT_WEIGHTS = (1.0, 1.0, 1.0, 1.0)  # pelvis, left hip, right hip, spine1 in the root fit
LIMB_END_WEIGHT = 2.0  # an ankle/wrist miss counts double when placing the knee/elbow
SPINE_BLEND = {3: 1.0 / 3.0, 6: 2.0 / 3.0}  # share of the chest's left-right axis per spine joint
_LIMB_OF = {l[0]: l for l in LIMBS}   # limb root -> its limb
_HINGE_OF = {l[1]: l for l in LIMBS}  # knee/elbow -> its limb
_EPS = 1e-9
IK_WINDOW = 512  # frames per batch in ``solve_ik``: ~25 s at 20 fps, ~60 MB of Jacobians at most


@dataclass
class IKResult:
    rotations: np.ndarray    # (T,24,3,3) local rotations
    transl: np.ndarray       # (T,3) metres, added to FK (root stays at its rest position in FK)
    joint_error: np.ndarray  # (T,22) metres, |FK + transl - target| per joint
    mean_error_cm: float

    def per_joint_error_cm(self) -> np.ndarray:
        """(22,) mean error of each joint over the frames, centimetres."""
        return self.joint_error.mean(0) * 100.0


# -- small batched rotation helpers (torch, (...,3) vectors) -------------------------------------
def _unit(v: torch.Tensor) -> torch.Tensor:
    return v / torch.linalg.norm(v, dim=-1, keepdim=True).clamp_min(_EPS)


def _align_two(a1, a2, b1, b2) -> torch.Tensor:
    """Rotation taking a1 exactly onto b1's direction and a2 as close as possible to b2."""
    return orthonormal_frame(b1, b2) @ orthonormal_frame(a1, a2).transpose(-1, -2)


def _kabsch(src: torch.Tensor, dst: torch.Tensor, weight: torch.Tensor | None = None) -> torch.Tensor:
    """Rotation (T,3,3) best mapping the vectors src (n,3) onto dst (T,n,3) (weighted least squares)."""
    if weight is not None:
        src = src * weight[:, None]
    h = torch.einsum("ni,tnj->tij", src, dst)
    u, _, vt = torch.linalg.svd(h)
    d = torch.sign(torch.linalg.det(vt.transpose(-1, -2) @ u.transpose(-1, -2)))
    d = torch.where(d == 0, torch.ones_like(d), d)
    fix = torch.diag_embed(torch.stack([torch.ones_like(d), torch.ones_like(d), d], -1))
    return vt.transpose(-1, -2) @ fix @ u.transpose(-1, -2)


def _smoothstep(x: torch.Tensor, lo: float, hi: float) -> torch.Tensor:
    t = ((x - lo) / (hi - lo)).clamp(0, 1)
    return t * t * (3 - 2 * t)




# -- input checks --------------------------------------------------------------------------------
def _prepare(joints, rest_joints, parents):
    j = torch.as_tensor(np.asarray(joints, dtype=np.float64) if not torch.is_tensor(joints) else joints)
    r = torch.as_tensor(np.asarray(rest_joints, dtype=np.float64) if not torch.is_tensor(rest_joints)
                        else rest_joints)
    j, r = j.detach().double(), r.detach().double()
    if j.dim() == 2:
        j = j[None]
    if j.dim() != 3 or j.shape[-1] != 3 or j.shape[1] not in (NUM_BODY_JOINTS, NUM_JOINTS):
        raise ShapeMoveError(f"IK joints must be (frames, 22, 3) metres, got shape {tuple(j.shape)}")
    if j.shape[0] == 0:
        raise ShapeMoveError("IK joints have no frames")
    if r.dim() == 3 and r.shape[0] == 1:
        r = r[0]
    if tuple(r.shape) != (NUM_JOINTS, 3):
        raise ShapeMoveError(f"rest_joints must be (24, 3) metres, got shape {tuple(r.shape)}")
    if not (torch.isfinite(j).all() and torch.isfinite(r).all()):
        raise ShapeMoveError("IK input contains NaN or infinite values")
    parents = np.asarray(parents, dtype=np.int64)
    if not np.array_equal(parents, PARENTS):
        raise ShapeMoveError("IK supports the SMPL 24-joint tree only (parents = skeleton.PARENTS)")
    return j[:, :NUM_BODY_JOINTS], r, parents


def _fk(rot: torch.Tensor, rest: torch.Tensor, parents, transl: torch.Tensor) -> torch.Tensor:
    pos, _ = forward_kinematics(rot, rest.expand(rot.shape[0], -1, -1), parents)
    return pos[:, :NUM_BODY_JOINTS] + transl[:, None]


def _result(rot, transl, target, pos) -> IKResult:
    """IKResult of a pose whose posed joints (T,22,3) are ``pos``."""
    err = torch.linalg.norm(pos.detach() - target, dim=-1)
    return IKResult(rotations=rot.detach().float().numpy(), transl=transl.detach().float().numpy(),
                    joint_error=err.float().numpy(), mean_error_cm=float(err.mean()) * 100.0)


def hinge_axes(rest_joints, parents=PARENTS) -> dict:
    """{knee/elbow joint index: (3,) unit hinge axis} in the rest frame: the knee's +X and the
    elbows' -Y/+Y made orthogonal to the upper bone (thigh/upper arm). Rotating the knee/elbow
    about this axis by a positive angle flexes it; ``solve_ik`` recovers such rotations exactly."""
    rest = torch.as_tensor(np.asarray(rest_joints, dtype=np.float64)).reshape(NUM_JOINTS, 3)
    out = {}
    for root, mid, _, axis in LIMBS:
        a = _unit(rest[mid] - rest[parents[mid]])
        h = torch.tensor(axis, dtype=torch.float64)
        out[mid] = _unit(h - (h @ a) * a).numpy()
    return out


def rest_with_bone_lengths(rest_joints, lengths) -> np.ndarray:
    """(24,3) rest joints with the 21 body bones (``skeleton.BODY_BONES`` order, metres) set to
    ``lengths``, directions kept; the hands keep the forearm's scale. A stand-in for a body fit
    when the exact bone lengths of a target skeleton are wanted (e.g. ``Motion22.bone_lengths()[1:]``)."""
    rest = np.asarray(rest_joints, dtype=np.float64).reshape(NUM_JOINTS, 3)
    lengths = np.asarray(lengths, dtype=np.float64).reshape(-1)
    if lengths.shape != (NUM_BODY_JOINTS - 1,) or not np.all(np.isfinite(lengths)) or np.any(lengths <= 0):
        raise ShapeMoveError(f"need {NUM_BODY_JOINTS - 1} positive bone lengths in metres")
    offs = rest.copy()
    offs[1:] = rest[1:] - rest[PARENTS[1:]]
    out = rest.copy()
    for j in range(1, NUM_JOINTS):
        bone = j if j < NUM_BODY_JOINTS else PARENTS[j]
        scale = lengths[bone - 1] / max(np.linalg.norm(rest[bone] - rest[PARENTS[bone]]), 1e-9)
        out[j] = out[PARENTS[j]] + offs[j] * scale
    return out


def bone_turn_deg(rotations, transl, rest_joints, joints, parents=PARENTS) -> np.ndarray:
    """(T,19) angle in degrees between each posed bone and the target's bone for the 22-joint
    body, leaving out the pelvis's own child bones (those are the body's rest layout). A pose
    quality measure next to the joint error: 0 means every bone points as in the targets."""
    rot = torch.as_tensor(np.asarray(rotations), dtype=torch.float64)
    rest = torch.as_tensor(np.asarray(rest_joints, dtype=np.float64)).reshape(NUM_JOINTS, 3)
    pos = _fk(rot, rest, parents, torch.as_tensor(np.asarray(transl), dtype=torch.float64)).numpy()
    tgt = np.asarray(joints, dtype=np.float64)[:, :NUM_BODY_JOINTS]
    bones = np.array([j for j in range(1, NUM_BODY_JOINTS) if parents[j] != 0])
    a = pos[:, bones] - pos[:, parents[bones]]
    b = tgt[:, bones] - tgt[:, parents[bones]]
    cos = (a * b).sum(-1) / np.maximum(np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1), 1e-12)
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


# -- analytic solve ------------------------------------------------------------------------------
@functools.lru_cache(maxsize=4)
def _tree(parents: tuple):
    """(children of each joint within the 22-joint body, the solve order: groups of joints whose
    parents are already solved and that take the same kind of solve, e.g. both hips)."""
    kids = [[c for c in range(1, NUM_BODY_JOINTS) if parents[c] == j] for j in range(NUM_JOINTS)]
    kind = lambda j: ("many" if len(kids[j]) > 1 else "spine" if j in SPINE_BLEND else "limb" if j in _LIMB_OF  # noqa: E731
                      else "hinge" if j in _HINGE_OF else "leaf" if not kids[j] else "swing")
    groups, done, pending = [], {0}, list(range(1, NUM_JOINTS))
    while pending:
        j = pending[0]
        grp = [j] if kind(j) == "many" else [k for k in pending if parents[k] in done and kind(k) == kind(j)]
        groups.append((kind(j), tuple(grp)))
        done |= set(grp)
        pending = [k for k in pending if k not in done]
    return kids, tuple(groups)


def fit_root(target: torch.Tensor, rest: torch.Tensor, parents) -> tuple[torch.Tensor, torch.Tensor]:
    """The root's world rotation (T,3,3) and position (T,3): a rigid fit (rotation + translation)
    of the pelvis and its children (hips, spine1; ``ROOT_WEIGHTS``) of ``rest`` (24,3) onto
    ``target`` (T,22,3), float64. With another body's pelvis layout this shares the mismatch
    instead of piling it onto the hips."""
    group = [0] + list(_tree(tuple(int(p) for p in parents))[0][0])
    w = torch.tensor(ROOT_WEIGHTS, dtype=target.dtype)[:, None]
    c_rest = (rest[group] * w).sum(0) / w.sum()
    c_tgt = (target[:, group] * w).sum(1) / w.sum()
    rot = _kabsch(rest[group] - c_rest, target[:, group] - c_tgt[:, None], w[:, 0])
    return rot, c_tgt + rot @ (rest[0] - c_rest)


def analytic_ik(target: torch.Tensor, rest: torch.Tensor, parents, max_turn_deg: float = 30.0):
    """target (T,22,3), rest (24,3) float64 -> local rotations (T,24,3,3), transl (T,3)."""
    T = target.shape[0]
    dt = target.dtype
    offs = rest.clone()
    offs[1:] = rest[1:] - rest[parents[1:]]
    kids, groups = _tree(tuple(int(p) for p in parents))
    axes = hinge_axes(rest, parents)
    hinge_axis = {j: torch.as_tensor(axes[l[1]], dtype=dt) for l in LIMBS for j in l[:2]}  # limb root and hinge
    ex = torch.tensor([1.0, 0, 0], dtype=dt)
    # chest orientation straight from the targets (used to spread the spine twist)
    chest = _kabsch(offs[kids[9]], target[:, kids[9]] - target[:, 9:10])

    G = [None] * NUM_JOINTS  # world rotations (T,3,3)
    P = [None] * NUM_JOINTS  # FK positions (T,3)
    G[0], P[0] = fit_root(target, rest, parents)
    # a group (e.g. the left and right knee) is solved as one batch of 2T frames: the same arithmetic, fewer calls
    cat = lambda xs: xs[0] if len(xs) == 1 else torch.cat(xs, 0)  # noqa: E731
    per = lambda x: x.expand(T, *x.shape)  # noqa: E731  a per-joint constant, one row per frame
    for kind, js in groups:
        ps = [parents[j] for j in js]
        gp = cat([G[p] for p in ps])
        pj = cat([P[p] for p in ps]) + (gp @ cat([per(offs[j]) for j in js])[..., None])[..., 0]
        for i, j in enumerate(js):
            P[j] = pj[i * T:(i + 1) * T]
        if kind == "leaf":
            for j, p in zip(js, ps):
                G[j] = G[p]
            continue
        ch = [kids[j][0] for j in js]
        if kind == "many":
            (j,) = js
            bone = torch.linalg.norm(target[:, kids[j]] - target[:, j:j + 1], dim=-1).min(1, keepdim=True).values
            aim = target[:, kids[j]] + _aim_shift(target[:, j] - P[j], bone, max_turn_deg)[:, None]
            G[j] = _kabsch(offs[list(kids[j])], aim - P[j][:, None])
            continue
        tj, tc = cat([target[:, j] for j in js]), cat([target[:, c] for c in ch])
        shift = _aim_shift(tj - pj, torch.linalg.norm(tc - tj, dim=-1, keepdim=True), max_turn_deg)
        aim = tc + shift  # child targets, moved along when j is off its own
        oc = cat([per(offs[c]) for c in ch])
        if kind == "spine":
            (j,) = js
            s = SPINE_BLEND[j]
            side = (1 - s) * (G[0] @ ex) + s * (chest @ ex)
            gj = _align_two(oc, ex.expand(T, 3), aim - pj, side)
        elif kind == "limb":
            h = cat([per(hinge_axis[j]) for j in js])
            end = cat([target[:, _LIMB_OF[j][2]] for j in js]) + shift
            gj = _limb_root(h, oc, cat([per(offs[_LIMB_OF[j][2]]) for j in js]), aim, end, pj, gp)
        elif kind == "hinge":
            h = cat([per(hinge_axis[j]) for j in js])
            gj = _align_two(oc, h, aim - pj, (gp @ h[..., None])[..., 0])
        else:
            gj = rotation_between((gp @ oc[..., None])[..., 0], aim - pj) @ gp
        for i, j in enumerate(js):
            G[j] = gj[i * T:(i + 1) * T]
    rot = torch.stack([G[0]] + [G[parents[j]].transpose(-1, -2) @ G[j] for j in range(1, NUM_JOINTS)], 1)
    return rot, P[0] - rest[0]


def _aim_shift(miss: torch.Tensor, bone: torch.Tensor, max_turn_deg: float) -> torch.Tensor:
    """(T,3) shift for the child targets of a joint that FK put ``miss`` = target - FK position
    away from its target. Aiming a bone (target length ``bone`` (T,1)) at its child's target from
    the wrong place would turn it away from the target bone's direction (a too-long spine
    folds the neck); the child targets are moved along with the miss as far as needed to keep
    that turn below ``max_turn_deg``, so small misses are still corrected and big ones copied."""
    e = torch.linalg.norm(miss, dim=-1, keepdim=True)
    beta = (bone * np.sin(np.radians(min(max_turn_deg, 90.0))) / e.clamp_min(_EPS)).clamp(max=1.0)
    return -(1 - beta) * miss


def _limb_root(h, off_mid, off_end, t_mid, t_end, pj, gp):
    """World rotation of a hip/shoulder: aim at the knee/elbow target ``t_mid``, twist so that
    the knee/elbow bends about its hinge axis ``h`` towards ``t_end``; near-straight limbs keep
    the minimal swing's twist. h, off_mid, off_end (rest hinge axis and bone offsets), t_mid,
    t_end, pj: (N,3); gp (N,3,3), the parent's world rotation."""
    a = _unit(off_mid)
    bj = _unit(_place_mid(pj, t_mid, t_end, off_mid, off_end) - pj)
    g0 = rotation_between((gp @ a[..., None])[..., 0], bj) @ gp
    u = (g0 @ h[..., None])[..., 0]                # hinge axis with the minimal twist
    p_mid = pj + torch.linalg.norm(off_mid, dim=-1, keepdim=True) * bj  # where FK will put the knee/elbow
    bk = _unit(t_end - p_mid)
    dvec = bk - (bk * bj).sum(-1, keepdim=True) * bj
    r = torch.linalg.norm(dvec, dim=-1, keepdim=True)  # sin of the bend angle
    d = dvec / r.clamp_min(_EPS)
    e = torch.cross(bj, d, dim=-1)                 # hinge direction for a flexion towards d
    flex = torch.cross(u, bj, dim=-1)               # flexion direction predicted by the swing
    # slightly bent limbs bending "backwards" are read as hyperextension, not as a half twist
    sign = torch.where(((d * flex).sum(-1, keepdim=True) >= 0) | (r > 0.5), 1.0, -1.0).to(bj.dtype)
    c = (_unit(off_end) * h).sum(-1, keepdim=True)  # rest lower bone's component along the hinge
    alpha = (c / r.clamp_min(_EPS)).clamp(-1, 1)
    w = alpha * d + sign * torch.sqrt(1 - alpha * alpha) * e
    s = _smoothstep(r, np.sin(np.radians(2.0)), np.sin(np.radians(12.0)))
    w = s * w + (1 - s) * u
    return _align_two(a, h, bj, w)


def _two_bone_mid(root, mid, end, off_mid, off_end):
    """Where to put the knee/elbow (T,3) so that the ankle/wrist lands on its target when it can:
    on the circle of positions at the body's bone lengths from the hip and the ankle, on the side
    of the target knee (the nearest point of that circle). Equals the target knee whenever the
    targets have the body's bone lengths."""
    l1, l2 = torch.linalg.norm(off_mid, dim=-1, keepdim=True), torch.linalg.norm(off_end, dim=-1, keepdim=True)
    v = end - root
    dist = torch.linalg.norm(v, dim=-1, keepdim=True)
    n = v / dist.clamp_min(_EPS)
    d = dist.clamp(abs(l1 - l2) + 1e-6, l1 + l2 - 1e-9)
    x = (l1 * l1 - l2 * l2 + d * d) / (2 * d)
    rho = torch.sqrt((l1 * l1 - x * x).clamp_min(0))
    m = (mid - root) - ((mid - root) * n).sum(-1, keepdim=True) * n
    mn = torch.linalg.norm(m, dim=-1, keepdim=True)
    ok = mn > 1e-6
    mid_new = root + x * n + rho * m / mn.clamp_min(_EPS)
    return torch.where(ok, mid_new, mid)


def _place_mid(root, mid, end, off_mid, off_end):
    """Knee/elbow target (T,3) for the FK hip/shoulder ``root``: aim straight at the target
    knee, or use the two-bone solution that also lands the ankle - whichever misses less
    (knee miss + LIMB_END_WEIGHT x ankle miss), frame by frame."""
    l1, l2 = torch.linalg.norm(off_mid, dim=-1, keepdim=True), torch.linalg.norm(off_end, dim=-1, keepdim=True)

    def misses(knee):
        return (torch.linalg.norm(knee - mid, dim=-1)
                + LIMB_END_WEIGHT * (torch.linalg.norm(end - knee, dim=-1) - l2[..., 0]).abs())

    direct = root + l1 * _unit(mid - root)
    two = _two_bone_mid(root, mid, end, off_mid, off_end)
    return torch.where((misses(two) <= misses(direct))[:, None], two, mid)


# -- refinement ----------------------------------------------------------------------------------
@functools.lru_cache(maxsize=4)
def _gn_structure(parents: tuple):
    """Sparsity of the refinement's Jacobian. Rows: the 22 joints, then the 22 bones (by child
    joint). Blocks (row, column): a joint k and each strict ancestor j of it that has a child in the
    22-joint body (the leaves' rotations move no body joint), the same for the bone ending at k,
    and joint k with the root translation (last column). Returns (rows, columns, kinds, ancestors,
    movers), kind 0 joint/ancestor, 1 bone/ancestor, 2 translation; cached per tree, so read only."""
    n = NUM_BODY_JOINTS
    movers = [j for j in range(n) if any(parents[c] == j for c in range(1, n))]
    col = {j: i for i, j in enumerate(movers)}
    rows, cols, kinds, anc = [], [], [], []
    for k in range(n):
        rows.append(k), cols.append(len(movers)), kinds.append(2), anc.append(0)
        j = parents[k]
        while j >= 0:
            rows += [k, n + k]
            cols += [col[j], col[j]]
            kinds += [0, 1]
            anc += [j, j]
            j = parents[j]
    rows, cols, kinds, anc = (torch.tensor(x) for x in (rows, cols, kinds, anc))
    return rows, cols, kinds, anc, torch.tensor(movers)


def refine(rot0, transl0, target, rest, parents, iters: int = 2, end_weight: float = 3.0, bone_weight: float = 1.0,
           free_turn_deg: float = 30.0, huber: float = 5e-3, damping: float = 1e-3, tol: float = 1e-3):
    """Up to ``iters`` damped Gauss-Newton steps per frame, batched over frames, on

        sum_k w_k huber(|FK_k - target_k|)  +  bone_weight^2 / 2 x sum_b (|bone_b - L_b u_b| - f_b)+^2 / 1 cm

    (w: ankles, feet and wrists ``end_weight``, contacts matter most; huber: quadratic below
    ``huber`` metres, linear above, as iteratively reweighted least squares; bone_b: the posed bone
    of length L_b, u_b the target bone's direction, for the bones ``bone_turn_deg`` counts; f_b the
    tip distance of a ``free_turn_deg`` turn): bones turn freely up to ``free_turn_deg`` from the
    targets' and are held beyond, so a body with other proportions spreads its misses instead of
    folding a chain to reach them. Closed-form Jacobian: turning joint j's subtree by a small
    world rotation w moves a descendant k by w x (p_k - p_j); the root translation moves all. One
    (T,54,54) Cholesky solve per step; ``damping`` (Levenberg-Marquardt, relative to the diagonal).
    A frame keeps its pose when a step does not lower its loss; stops early when the total loss
    drops by less than ``tol`` (relative); no step at all when every joint is within 0.01 mm of its
    target. Returns (rotations, transl, posed joints (T,22,3))."""
    T, n = rot0.shape[0], NUM_BODY_JOINTS
    dt = rot0.dtype
    offs = rest.clone()
    offs[1:] = rest[1:] - rest[parents[1:]]
    par = torch.as_tensor(parents[:n])
    rows, cols, kinds, anc, movers = _gn_structure(tuple(int(p) for p in parents))
    m = len(movers)
    nb = m + 1  # column blocks: the movers' turns, then the translation
    jrow = torch.where(kinds == 1, par[rows % n].clamp_min(0), anc)  # bone rows turn about the bone's parent...
    krow = rows % n                                                   # ...and move joint k
    weight = torch.ones(n, dtype=dt)
    weight[END_JOINTS] = end_weight
    # bone rows (indexed by the child joint); the pelvis's own child bones are the rest layout
    bw = torch.tensor([0.0 if c == 0 or parents[c] == 0 else bone_weight for c in range(n)], dtype=dt)
    blen = torch.linalg.norm(offs[:n], dim=-1)
    ub = _unit(target - target[:, par.clamp_min(0)]) * blen[:, None]  # (T,22,3) wanted bone vectors
    free = blen * 2 * np.sin(np.radians(free_turn_deg) / 2)  # bone-tip distance of a free turn
    turn = kinds != 2                                                 # skew blocks (not the translation's)
    # flat offsets inside a (3, nb*3) block row: the skew's six entries (row-major), the identity's three
    skew_at = torch.tensor([1, 2, 3, 5, 6, 7]) // 3 * (nb * 3) + torch.tensor([1, 2, 3, 5, 6, 7]) % 3
    eye_at = torch.arange(3) * (nb * 3) + torch.arange(3)

    def terms(pos):
        res = target - pos
        bres = ub - (pos - pos[:, par.clamp_min(0)])
        blen_res = torch.linalg.norm(bres, dim=-1, keepdim=True)
        bres = bres * (1 - free[:, None] / blen_res.clamp_min(1e-9)).clamp_min(0)  # hinge: past the free turn
        dist = torch.linalg.norm(res, dim=-1)
        hub = torch.where(dist < huber, dist * dist / (2 * huber), dist - huber / 2)
        loss = (hub * weight).sum(-1) + 50.0 * ((bres ** 2).sum(-1) * bw ** 2).sum(-1)
        return res, bres, dist, loss

    rot, tr = rot0.clone(), transl0.clone()
    pos, G = forward_kinematics_offsets(rot[:, :NUM_BODY_JOINTS], offs, parents, tr)
    res, bres, dist, loss = terms(pos)
    lam = torch.full((T,), damping, dtype=torch.float32)  # per frame: up when a step fails
    for _ in range(iters if dist.max() > 1e-5 else 0):   # already on the targets (to 0.01 mm): nothing to do
        # (T,44) joint IRLS weights; bone weights where the bone is past its free turn (the
        # hinge has no curvature inside the free cone)
        w = torch.cat([weight / dist.clamp_min(huber), 100.0 * bw ** 2 * (bres != 0).any(-1)], 1).float()
        # blocks: d (w x (p_k - p_j)) / dw = skew(p_j - p_k) for an ancestor j of joint k; the bone
        # (p, k) turns by skew(p_p - p_k); the translation moves joints by I (float32 is plenty
        # for a step: the loss and the pose stay float64)
        x, y, z = (pos[:, jrow[turn]] - pos[:, krow[turn]]).float().unbind(-1)
        # bone rows only for the bones past their free turn in some frame (usually a few)
        keep = torch.cat([torch.ones(n, dtype=torch.bool), (bres != 0).any(-1).any(0)])
        slot = torch.cumsum(keep, 0) - 1
        nrow = int(keep.sum()) * 3
        # J (T, rows x 3, 54) filled in place: the six entries of each skew block, the translation's ones
        J = torch.zeros(T, nrow * nb * 3, dtype=torch.float32)
        on = keep[rows[turn]]
        base = (slot[rows[turn]] * 3 * nb * 3 + cols[turn] * 3)[on]
        J[:, (base[:, None] + skew_at).reshape(-1)] = torch.stack([-z, y, z, -x, -y, x], -1)[:, on].reshape(T, -1)
        J[:, (slot[rows[~turn]] * 3 * nb * 3 + cols[~turn] * 3)[:, None] + eye_at] = 1.0
        J = J.reshape(T, nrow, nb * 3)
        wJ = w[:, keep].repeat_interleave(3, dim=1)[..., None] * J
        H = J.transpose(1, 2) @ wJ
        g = wJ.transpose(1, 2) @ torch.cat([res, bres], 1)[:, keep].float().reshape(T, -1, 1)
        diag = torch.diagonal(H, dim1=1, dim2=2)
        # relative damping + a floor for directions the joints don't see (a straight limb's twist)
        diag.add_(lam[:, None] * diag + 1e-3 * diag.mean(-1, keepdim=True))
        L, info = torch.linalg.cholesky_ex(H)
        step = torch.cholesky_solve(g, L)[..., 0].double()
        step = torch.where((info == 0)[:, None], step, torch.zeros_like(step))
        omega = step[:, :m * 3].reshape(T, m, 3, 1)
        local = (G[:, movers].transpose(-1, -2) @ omega)[..., 0]       # world turn -> joint frame
        new_rot = rot.clone()
        new_rot[:, movers] = rot[:, movers] @ axis_angle_to_matrix(local)
        new_tr = tr + step[:, m * 3:]
        new_pos, new_G = forward_kinematics_offsets(new_rot[:, :NUM_BODY_JOINTS], offs, parents, new_tr)
        new_res, new_bres, new_dist, new_loss = terms(new_pos)
        ok = new_loss < loss
        lam = torch.where(ok, lam / 3, lam * 10).clamp(1e-6, 1e6)
        rot = torch.where(ok[:, None, None, None], new_rot, rot)
        tr = torch.where(ok[:, None], new_tr, tr)
        pos = torch.where(ok[:, None, None], new_pos, pos)
        G = torch.where(ok[:, None, None, None], new_G, G)
        res = torch.where(ok[:, None, None], new_res, res)
        bres = torch.where(ok[:, None, None], new_bres, bres)
        dist = torch.where(ok[:, None], new_dist, dist)
        gain = (loss - torch.minimum(new_loss, loss)).sum() / loss.sum().clamp_min(1e-12)
        loss = torch.minimum(new_loss, loss)
        if gain < tol:
            break
    return rot, tr, pos


def solve_ik(joints, rest_joints, parents=PARENTS, refine_iters: int = 2, max_turn_deg: float = 30.0,
             window: int = IK_WINDOW) -> IKResult:
    """joints (T,22,3) metres Y-up; rest_joints (24,3) of the target body (e.g.
    ``BodyModel.rest_joints(betas)[0]``). Analytic IK then up to ``refine_iters`` Gauss-Newton
    steps (``refine``; 0 = analytic only; skipped when the analytic error is already below 0.01 mm).
    Each step costs about as much as the analytic solve: 2 keep ``bench ik``'s >= 30x over the
    100-iteration L-BFGS baseline (x32.9, 2.38 cm vs its 2.57 cm); 10 (what the data builder
    passes) lowers the error further.
    ``max_turn_deg``: when the body's proportions differ from the targets', how far (degrees) a
    bone may turn away from the target bone's direction to reach a target joint; larger trades
    natural poses (a too-long spine would fold the neck) for lower joint error. Irrelevant when
    the body fits. Bad input raises ShapeMoveError. ``window``: frames solved per batch (memory
    is bounded by it; each window's refinement stops on its own progress).
    Returns local rotations (T,24,3,3) and transl (T,3) such that FK + transl ~ joints."""
    target, rest, parents = _prepare(joints, rest_joints, parents)
    parts = []
    with one_torch_thread(), torch.no_grad():
        # frames are solved independently: ``window`` at a time keeps the Jacobians' memory a
        # constant (a 10-minute take at once needed gigabytes); a clip up to a window is one batch
        for s in range(0, target.shape[0], window):
            tw = target[s:s + window]
            rot, transl = analytic_ik(tw, rest, parents, max_turn_deg)
            if refine_iters > 0:
                rot, transl, pos = refine(rot, transl, tw, rest, parents, iters=refine_iters)
            else:
                pos = _fk(rot, rest, parents, transl)
            parts.append(_result(rot, transl, tw, pos))
    if len(parts) == 1:
        return parts[0]
    err = np.concatenate([p.joint_error for p in parts])
    return IKResult(rotations=np.concatenate([p.rotations for p in parts]),
                    transl=np.concatenate([p.transl for p in parts]), joint_error=err,
                    mean_error_cm=float(err.astype(np.float64).mean()) * 100.0)


def ik_lbfgs_baseline(joints, rest_joints, iters: int = 100, parents=PARENTS) -> IKResult:
    """SMPLify-style baseline: LBFGS on axis-angle from identity rotations (transl started at
    the pelvis), ``iters`` iterations over all frames at once, small L2 pose prior."""
    target, rest, parents = _prepare(joints, rest_joints, parents)
    T = target.shape[0]
    aa = torch.zeros(T, NUM_JOINTS, 3, dtype=target.dtype, requires_grad=True)
    tr = (target[:, 0] - rest[0]).clone().requires_grad_(True)
    opt = torch.optim.LBFGS([aa, tr], lr=1.0, max_iter=iters, line_search_fn="strong_wolfe",
                            tolerance_grad=1e-12, tolerance_change=1e-15)

    def closure():
        opt.zero_grad()
        pos = _fk(axis_angle_to_matrix(aa), rest, parents, tr)
        loss = ((pos - target) ** 2).sum(-1).mean() + 1e-6 * (aa ** 2).sum(-1).mean()
        loss.backward()
        return loss

    with one_torch_thread():
        opt.step(closure)
        rot = axis_angle_to_matrix(aa.detach())
        return _result(rot, tr.detach(), target, _fk(rot, rest, parents, tr.detach()))
