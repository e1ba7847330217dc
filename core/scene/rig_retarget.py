"""Bake a ShapeMove motion onto the user's own armature (Blender-free maths; the addon reads the
armature into a ``bone_map.ArmatureRest`` and writes the keys).

For every mapped bone b playing SMPL joint j (``bone_map``):

- **Rest alignment** (A-pose, T-pose, any bone roll): Q_b is the world rotation taking the bone's
  rest frame onto the source's rest frame at j; both frames are built from the same two
  directions, the limb direction (j -> the next mapped joint down the body: hip -> knee, shoulder ->
  elbow, ...) and the body's forward (left for bones that point forward, the feet). Joints with
  nothing mapped below (wrists, head, toes) keep their rest relation to their parent joint.
- **Rotation**: world rotation of bone b at frame t = G_j(t) Q_b B_b, with G_j the source
  joint's world rotation from its rest pose and B_b the bone's rest orientation; the source is
  first turned about the vertical so its forward is the armature's forward. A bone spanning
  unmapped source joints (one chest bone for spine2 + spine3) is swung further so that it points
  from joint j at the source's next mapped joint.
- **Root motion and height** are scaled by s = target leg length / source leg length (hip ->
  knee -> ankle); the source floor (y = 0) lands on the armature's floor (the object origin's
  height) with the difference of ankle heights over the soles corrected; the pelvis bone's
  head keeps its rest offset from the source pelvis, turning with it.
- **Feet planted**: where the source's feet rest on the floor (``core.motion.contacts``), each
  ankle is held at one point per contact run (faded in and out over a few frames) by two-bone IK
  on the thigh and shin, keeping the knee's bend plane; the foot keeps its world rotation.

Unmapped bones keep their rest pose relative to their parents. The output is one quaternion per
mapped bone and frame (pose-bone ``rotation_quaternion``, (w, x, y, z)) and the pelvis bone's
``location``, ready for ``shapemove_addon.keyframes.write_pose_action``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body.skeleton import PARENTS
from ..errors import ShapeMoveError
from ..geometry.rotations import (axis_angle_to_matrix, make_continuous, matrix_to_quaternion, orthonormal_frame,
                                 rotation_between)
from ..motion.contacts import detect_contacts, floor_levels, runs
from .axes import Y_UP_TO_Z_UP
from .bone_map import SMPL22, ArmatureRest, check_map

PAR22 = np.asarray(PARENTS[:22])
# the joint below j whose direction aligns the bone (first mapped one along these chains)
DOWN = {0: (3, 6, 9, 12, 15), 3: (6, 9, 12, 15), 6: (9, 12, 15), 9: (12, 15), 12: (15,),
        1: (4, 7), 4: (7,), 7: (10,), 2: (5, 8), 5: (8,), 8: (11,),
        13: (16, 18, 20), 16: (18, 20), 18: (20,), 14: (17, 19, 21), 17: (19, 21), 19: (21,)}
FADE = 4  # frames over which a planted ankle blends back into the free motion


@dataclass
class RigBake:
    """bones: mapped bone names, the pelvis bone first; quats (T,K,4) pose-bone rotations;
    root_offset (T,3): armature-space offset of the pelvis bone's head from its rest position
    (``write_pose_action``'s ``transl``); joints (T,22,3) world positions (Blender axes) of the
    mapped bones' heads after the bake (NaN for unmapped joints); expected (T,22,3): the source
    joints scaled and placed on the armature (what ``joints`` equals on a rig with the source's
    proportions, before feet planting); contacts (T,4) of the source (ankles, balls);
    scale: target / source leg length; heading: radians the source was turned about the vertical."""

    bones: list
    quats: np.ndarray
    root_offset: np.ndarray
    joints: np.ndarray
    expected: np.ndarray
    contacts: np.ndarray
    scale: float
    heading: float
    fps: float


def source_skeleton(motion):
    """(joints (T,22,3) Y-up, world rotations (T,22,3,3) from the rest pose, rest joints (22,3))
    of a ``motion_file.Motion`` (the rest skeleton recovered from its joints and rotations)."""
    P = np.asarray(motion.joints, dtype=np.float64)[:, :22]
    R = axis_angle_to_matrix(np.asarray(motion.poses, dtype=np.float64)[:, :22])
    G = np.empty_like(R)
    for j in range(22):
        G[:, j] = R[:, j] if PAR22[j] < 0 else G[:, PAR22[j]] @ R[:, j]
    rest = np.zeros((22, 3))
    rest[0] = np.mean(P[:, 0] - np.asarray(motion.transl, dtype=np.float64), axis=0)
    for j in range(1, 22):
        p = PAR22[j]
        off = np.einsum("tji,tj->ti", G[:, p], P[:, j] - P[:, p]).mean(0)
        rest[j] = rest[p] + off
    return P, G, rest


def _yaw(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def _two_bone_ik(H, K, A, target, a, b):
    """New knee positions (T,3) so that |K'-H| = a, |A'-K'| = b and A' = target (clamped to reach),
    keeping the plane of H, K and the target."""
    d = target - H
    c = np.linalg.norm(d, axis=-1, keepdims=True)
    c_cl = np.clip(c, abs(a - b) + 1e-6, a + b - 1e-6)
    u = d / np.maximum(c, 1e-12)
    w = (K - H) - np.sum((K - H) * u, -1, keepdims=True) * u
    w = w / np.maximum(np.linalg.norm(w, axis=-1, keepdims=True), 1e-12)
    cos_a = np.clip((a * a + c_cl ** 2 - b * b) / (2 * a * c_cl), -1, 1)
    knee = H + a * (cos_a * u + np.sqrt(1 - cos_a ** 2) * w)
    return knee, H + c_cl * u


class _Target:
    """The armature in world space, posed by world rotations of its mapped bones."""

    def __init__(self, arm: ArmatureRest):
        self.arm = arm
        M = arm.matrix_world
        self.lin = M[:3, :3]
        scale = np.cbrt(abs(np.linalg.det(self.lin)))
        if not scale > 0:
            raise ShapeMoveError("the armature object has zero scale")
        self.obj_rot = self.lin / scale
        self.heads = arm.heads @ self.lin.T + M[:3, 3]
        self.rest = self.obj_rot @ arm.rest_rot  # world rest orientation of each bone
        u, _, vt = np.linalg.svd(self.rest)
        self.rest = u @ vt

    def pose(self, world_rot: dict, root_bone: int, root_head: np.ndarray):
        """World rotations (T,J,3,3) and heads (T,J,3) of every bone: mapped bones take
        ``world_rot``, the others follow their parents; ancestors of the root bone stay at rest."""
        arm = self.arm
        T = len(root_head)
        J = len(arm.names)
        rot = np.empty((T, J, 3, 3))
        head = np.empty((T, J, 3))
        for b in range(J):
            p = int(arm.parents[b])
            if b == root_bone:
                head[:, b] = root_head
            elif p >= 0:
                rel = self.rest[p].T @ (self.heads[b] - self.heads[p])
                head[:, b] = head[:, p] + rot[:, p] @ rel
            else:
                head[:, b] = self.heads[b]
            if b in world_rot:
                rot[:, b] = world_rot[b]
            elif p >= 0:
                rot[:, b] = rot[:, p] @ (self.rest[p].T @ self.rest[b])
            else:
                rot[:, b] = self.rest[b]
        return rot, head


def retarget_to_armature(motion, arm: ArmatureRest, mapping: dict, plant_feet: bool = True) -> RigBake:
    """Bake ``motion`` (``motion_file.Motion``) onto ``arm`` with ``mapping`` {SMPL joint: bone}."""
    check_map(mapping, arm.names)
    P, G, rest = source_skeleton(motion)
    T = len(P)
    C = Y_UP_TO_Z_UP
    P = P @ C.T
    G = C @ G @ C.T
    rest = rest @ C.T
    tgt = _Target(arm)
    jid = {n: i for i, n in enumerate(SMPL22)}
    bone_of = {jid[j]: arm.index(b) for j, b in mapping.items()}
    for b in bone_of.values():
        if b != bone_of[0] and bone_of[0] not in _ancestors(arm.parents, b):
            raise ShapeMoveError(f"bone {arm.names[b]!r} is not below the pelvis bone {arm.names[bone_of[0]]!r}: "
                                 "it would not move with the body; map the bone that all others hang from as pelvis")
    H_t = tgt.heads

    # heading: the source's forward onto the armature's (left = up x forward, Z up)
    up = np.array([0.0, 0.0, 1.0])

    def forward(left):
        f = np.cross(left, up)
        n = np.linalg.norm(f)
        if n < 1e-9:
            raise ShapeMoveError("the hip bones stand one above the other: cannot tell which way the armature faces")
        return f / n

    f_s = forward(rest[1] - rest[2])
    f_t = forward(H_t[bone_of[1]] - H_t[bone_of[2]])
    heading = float(np.arctan2(np.cross(f_s, f_t)[2], np.dot(f_s, f_t)))
    Y = _yaw(heading)
    P = P @ Y.T
    G = Y @ G @ Y.T
    rest = rest @ Y.T
    left = np.cross(up, f_t)

    # scale by the legs; floor to floor
    def leg(pts):
        return np.mean([np.linalg.norm(pts[h] - pts[k]) + np.linalg.norm(pts[k] - pts[a])
                        for h, k, a in ((1, 4, 7), (2, 5, 8))])

    s = leg({j: H_t[b] for j, b in bone_of.items()}) / leg(rest)
    floor_t = float(arm.matrix_world[2, 3])
    ankle_t = np.mean([H_t[bone_of[7]][2], H_t[bone_of[8]][2]]) - floor_t
    ankle_s = float(floor_levels(P @ C)[0])  # the source ankles' height when standing on the floor
    origin = np.array([arm.matrix_world[0, 3], arm.matrix_world[1, 3], floor_t + ankle_t - s * ankle_s])
    expected = origin + s * P

    # rest alignment per mapped joint
    Q = {}
    for j in range(22):
        if j not in bone_of:
            continue
        below = next((c for c in DOWN.get(j, ()) if c in bone_of), None)
        if below is None:
            continue
        d_s = rest[below] - rest[j]
        d_t = H_t[bone_of[below]] - H_t[bone_of[j]]
        sec = left if abs(np.dot(d_s, f_t)) > 0.8 * np.linalg.norm(d_s) else f_t
        Q[j] = orthonormal_frame(d_s, sec) @ orthonormal_frame(d_t, sec).T
    for j in range(22):
        if j in bone_of and j not in Q:
            a = PAR22[j]
            while a >= 0 and a not in Q:
                a = PAR22[a]
            Q[j] = Q[a] if a >= 0 else np.eye(3)
    world = {bone_of[j]: G[:, j] @ Q[j] @ tgt.rest[bone_of[j]] for j in bone_of}
    # a bone that spans unmapped joints (Daz's chest: spine2 + spine3) turns by them too: its
    # direction follows the source's joint -> mapped joint below, the rest of its turn is joint j's
    for j in bone_of:
        below = next((c for c in DOWN.get(j, ()) if c in bone_of), None)
        if below is None or below == DOWN[j][0]:
            continue
        moved = np.einsum("tij,j->ti", G[:, j], rest[below] - rest[j])
        world[bone_of[j]] = rotation_between(moved, P[:, below] - P[:, j]) @ world[bone_of[j]]

    # the pelvis bone's head: the scaled source pelvis plus its rest offset, turning with the pelvis
    mid_t = 0.5 * (H_t[bone_of[1]] + H_t[bone_of[2]])
    mid_s = 0.5 * (rest[1] + rest[2])
    virtual_rest = mid_t + Q[0].T @ (s * (rest[0] - mid_s))
    delta = Q[0] @ (H_t[bone_of[0]] - virtual_rest)
    root_head = expected[:, 0] + G[:, 0] @ delta

    rot, head = tgt.pose(world, bone_of[0], root_head)
    contacts = detect_contacts(P @ Y @ C, motion.fps) if T >= 2 else np.zeros((T, 4), np.uint8)
    if plant_feet and T >= 2:
        world = _plant(tgt, world, rot, head, bone_of, contacts, root_head)
        rot, head = tgt.pose(world, bone_of[0], root_head)

    # world -> pose-bone channels (armature space)
    arm_rot = np.einsum("ji,tbjk->tbik", tgt.obj_rot, rot)
    bones = [bone_of[0]] + [b for j, b in sorted(bone_of.items()) if j != 0]
    quats = np.empty((T, len(bones), 4))
    for k, b in enumerate(bones):
        p = int(arm.parents[b])
        B_b = tgt.obj_rot.T @ tgt.rest[b]
        if p >= 0:
            B_p = tgt.obj_rot.T @ tgt.rest[p]
            basis = B_b.T @ B_p @ np.swapaxes(arm_rot[:, p], -1, -2) @ arm_rot[:, b]
        else:
            basis = B_b.T @ arm_rot[:, b]
        quats[:, k] = matrix_to_quaternion(basis)
    quats = make_continuous(quats)
    lin_inv = np.linalg.inv(tgt.lin)
    root_offset = (head[:, bone_of[0]] - tgt.heads[bone_of[0]]) @ lin_inv.T
    joints = np.full((T, 22, 3), np.nan)
    for j, b in bone_of.items():
        joints[:, j] = head[:, b]
    return RigBake([arm.names[b] for b in bones], quats, root_offset, joints, expected,
                   np.asarray(contacts), float(s), heading, float(motion.fps))


def _ancestors(parents, b):
    out = []
    b = int(parents[b])
    while b >= 0:
        out.append(b)
        b = int(parents[b])
    return out


def _plant(tgt, world, rot, head, bone_of, contacts, root_head):
    """World rotations with thigh and shin turned so each ankle holds still during its contacts."""
    world = dict(world)
    T = len(root_head)
    for side, (hj, kj, aj, cols) in enumerate(((1, 4, 7, (0, 2)), (2, 5, 8, (1, 3)))):
        hb, kb, ab = bone_of[hj], bone_of[kj], bone_of[aj]
        on = contacts[:, cols[0]].astype(bool) | contacts[:, cols[1]].astype(bool)
        A = head[:, ab]
        target = A.copy()
        weight = np.zeros(T)
        for s0, e0 in runs(on):
            anchor = A[s0:e0].mean(0)
            target[s0:e0] = anchor
            weight[s0:e0] = 1.0
            for d in range(1, FADE + 1):
                w = 1.0 - d / (FADE + 1)
                for t, edge in ((s0 - d, s0), (e0 - 1 + d, e0 - 1)):
                    if 0 <= t < T and weight[t] < w:
                        target[t], weight[t] = A[t] + w * (anchor - A[edge]), w
        moved = weight > 0
        if not moved.any():
            continue
        Hp, Kp = head[:, hb], head[:, kb]
        a = np.linalg.norm(tgt.heads[kb] - tgt.heads[hb])
        b = np.linalg.norm(tgt.heads[ab] - tgt.heads[kb])
        knee, reach = _two_bone_ik(Hp, Kp, A, target, a, b)
        R1 = rotation_between(Kp - Hp, knee - Hp)
        R2 = rotation_between(np.einsum("tij,tj->ti", R1, A - Kp), reach - knee)
        keep = ~moved
        R1[keep] = np.eye(3)
        R2[keep] = np.eye(3)
        world[hb] = R1 @ rot[:, hb]
        world[kb] = R2 @ R1 @ rot[:, kb]  # the ankle bone keeps its world rotation
    return world
