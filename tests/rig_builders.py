"""User-style armatures for the retarget tests (not a test module): Rigify (DEF- bones with twist
halves, control bones around them), Mixamo (with fingers), CC/iClone (twist leaves, BoneRoot) and
an unnamed rig, built on a body's 22 rest joints, scaled, in a T-pose or an A-pose, with random
bone rolls. Bones are (name, parent, head, tail, roll, deform) in Blender axes (Z up, facing -Y).
"""
from __future__ import annotations

import numpy as np

LEFT = {"hip": 1, "knee": 4, "ankle": 7, "foot": 10, "collar": 13, "shoulder": 16, "elbow": 18, "wrist": 20}
RIGHT = {"hip": 2, "knee": 5, "ankle": 8, "foot": 11, "collar": 14, "shoulder": 17, "elbow": 19, "wrist": 21}


def z_up(p):
    p = np.asarray(p, dtype=np.float64)
    return np.stack([p[..., 0], -p[..., 2], p[..., 1]], -1)


def posed_joints(rest_yup, scale=1.0, pose="T", lift=0.0, arm_angle=40.0):
    """(22,3) Z-up joints: the rest joints scaled about the origin, lifted by ``lift`` and, for
    an A-pose, the arms turned down by ``arm_angle`` degrees about each shoulder."""
    J = z_up(rest_yup) * scale + [0, 0, lift]
    if pose == "A":
        for side, sign in ((LEFT, 1), (RIGHT, -1)):
            a = np.radians(arm_angle) * -sign
            R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])  # about Y
            sh = J[side["shoulder"]].copy()
            for k in ("shoulder", "elbow", "wrist"):
                J[side[k]] = sh + R @ (J[side[k]] - sh)
    return J


def _bones_from(J, spec, rng):
    """spec: [(name, parent, head point, tail point, deform)] with points as joint indices or
    arrays -> bones with random rolls."""
    out = []
    for name, parent, h, t, deform in spec:
        h = J[h] if isinstance(h, (int, np.integer)) else np.asarray(h, dtype=np.float64)
        t = J[t] if isinstance(t, (int, np.integer)) else np.asarray(t, dtype=np.float64)
        out.append((name, parent, h, t, float(rng.uniform(-np.pi, np.pi)), deform))
    return out


def _hand_tip(J, side):
    return J[side["wrist"]] + 0.4 * (J[side["wrist"]] - J[side["elbow"]])


def _toe_tip(J, side):
    return J[side["foot"]] + np.array([0, -0.05, -0.01]) * np.linalg.norm(J[side["hip"]] - J[side["knee"]]) / 0.36


def _head_top(J):
    return J[15] + np.array([0, 0, 0.18])


def rigify(J, rng):
    mid = lambda a, b: 0.5 * (J[a] + J[b])  # noqa: E731
    spec = [("root", None, [0, 0, 0], [0, 0.3, 0], False),
            ("torso", "root", J[0] + [0, 0.3, 0], J[0] + [0, 0.5, 0], False),
            ("DEF-spine", "root", 0, 3, True), ("DEF-spine.001", "DEF-spine", 3, 6, True),
            ("DEF-spine.002", "DEF-spine.001", 6, 9, True), ("DEF-spine.003", "DEF-spine.002", 9, 12, True),
            ("DEF-spine.004", "DEF-spine.003", 12, mid(12, 15), True),
            ("DEF-spine.005", "DEF-spine.004", mid(12, 15), 15, True),
            ("DEF-spine.006", "DEF-spine.005", 15, _head_top(J), True)]
    for s, side in (("L", LEFT), ("R", RIGHT)):
        h, k, a, f = side["hip"], side["knee"], side["ankle"], side["foot"]
        c, sh, e, w = side["collar"], side["shoulder"], side["elbow"], side["wrist"]
        spec += [(f"DEF-pelvis.{s}", "DEF-spine", 0, J[h] + [0, -0.1, 0.1], True),
                 (f"DEF-thigh.{s}", "DEF-spine", h, mid(h, k), True),
                 (f"DEF-thigh.{s}.001", f"DEF-thigh.{s}", mid(h, k), k, True),
                 (f"DEF-shin.{s}", f"DEF-thigh.{s}.001", k, mid(k, a), True),
                 (f"DEF-shin.{s}.001", f"DEF-shin.{s}", mid(k, a), a, True),
                 (f"DEF-foot.{s}", f"DEF-shin.{s}.001", a, f, True),
                 (f"DEF-toe.{s}", f"DEF-foot.{s}", f, _toe_tip(J, side), True),
                 (f"DEF-shoulder.{s}", "DEF-spine.003", c, sh, True),
                 (f"DEF-upper_arm.{s}", f"DEF-shoulder.{s}", sh, mid(sh, e), True),
                 (f"DEF-upper_arm.{s}.001", f"DEF-upper_arm.{s}", mid(sh, e), e, True),
                 (f"DEF-forearm.{s}", f"DEF-upper_arm.{s}.001", e, mid(e, w), True),
                 (f"DEF-forearm.{s}.001", f"DEF-forearm.{s}", mid(e, w), w, True),
                 (f"DEF-hand.{s}", f"DEF-forearm.{s}.001", w, _hand_tip(J, side), True),
                 (f"ORG-thigh.{s}", "torso", h, k, False), (f"thigh_fk.{s}", "torso", h, k, False),
                 (f"MCH-foot_ik.{s}", "root", a, f, False)]
    return _bones_from(J, spec, rng)


def mixamo(J, rng, prefix="mixamorig:"):
    P = prefix
    spec = [(P + "Hips", None, 0, 3, True), (P + "Spine", P + "Hips", 3, 6, True),
            (P + "Spine1", P + "Spine", 6, 9, True), (P + "Spine2", P + "Spine1", 9, 12, True),
            (P + "Neck", P + "Spine2", 12, 15, True), (P + "Head", P + "Neck", 15, _head_top(J), True)]
    for s, side in (("Left", LEFT), ("Right", RIGHT)):
        h, k, a, f = side["hip"], side["knee"], side["ankle"], side["foot"]
        c, sh, e, w = side["collar"], side["shoulder"], side["elbow"], side["wrist"]
        spec += [(f"{P}{s}UpLeg", P + "Hips", h, k, True), (f"{P}{s}Leg", f"{P}{s}UpLeg", k, a, True),
                 (f"{P}{s}Foot", f"{P}{s}Leg", a, f, True), (f"{P}{s}ToeBase", f"{P}{s}Foot", f, _toe_tip(J, side), True),
                 (f"{P}{s}Shoulder", P + "Spine2", c, sh, True), (f"{P}{s}Arm", f"{P}{s}Shoulder", sh, e, True),
                 (f"{P}{s}ForeArm", f"{P}{s}Arm", e, w, True), (f"{P}{s}Hand", f"{P}{s}ForeArm", w, _hand_tip(J, side), True)]
        tip = _hand_tip(J, side)
        for fi, off in enumerate((-0.02, 0.0, 0.02)):
            prev = f"{P}{s}Hand"
            for n in range(1, 4):
                a0 = tip + (tip - J[w]) * 0.3 * (n - 1) + [0, off, 0]
                a1 = tip + (tip - J[w]) * 0.3 * n + [0, off, 0]
                name = f"{P}{s}Hand{('Index', 'Middle', 'Ring')[fi]}{n}"
                spec.append((name, prev, a0, a1, True))
                prev = name
    return _bones_from(J, spec, rng)


def cc(J, rng):
    spec = [("CC_Base_BoneRoot", None, [0, 0, 0], [0, 0, 0.2], True), ("CC_Base_Hip", "CC_Base_BoneRoot", 0, 3, True),
            ("CC_Base_Pelvis", "CC_Base_Hip", 0, J[0] - [0, 0, 0.1], True),
            ("CC_Base_Waist", "CC_Base_Hip", 3, 6, True), ("CC_Base_Spine01", "CC_Base_Waist", 6, 9, True),
            ("CC_Base_Spine02", "CC_Base_Spine01", 9, 12, True),
            ("CC_Base_NeckTwist01", "CC_Base_Spine02", 12, 0.5 * (J[12] + J[15]), True),
            ("CC_Base_NeckTwist02", "CC_Base_NeckTwist01", 0.5 * (J[12] + J[15]), 15, True),
            ("CC_Base_Head", "CC_Base_NeckTwist02", 15, _head_top(J), True)]
    for s, side in (("L", LEFT), ("R", RIGHT)):
        h, k, a, f = side["hip"], side["knee"], side["ankle"], side["foot"]
        c, sh, e, w = side["collar"], side["shoulder"], side["elbow"], side["wrist"]
        p = f"CC_Base_{s}_"
        spec += [(p + "Thigh", "CC_Base_Pelvis", h, k, True), (p + "Calf", p + "Thigh", k, a, True),
                 (p + "Foot", p + "Calf", a, f, True), (p + "ToeBase", p + "Foot", f, _toe_tip(J, side), True),
                 (p + "ThighTwist01", p + "Thigh", h, 0.5 * (J[h] + J[k]), True),
                 (p + "Clavicle", "CC_Base_Spine02", c, sh, True), (p + "Upperarm", p + "Clavicle", sh, e, True),
                 (p + "UpperarmTwist01", p + "Upperarm", sh, 0.5 * (J[sh] + J[e]), True),
                 (p + "Forearm", p + "Upperarm", e, w, True),
                 (p + "ForearmTwist01", p + "Forearm", 0.5 * (J[e] + J[w]), w, True),
                 (p + "Hand", p + "Forearm", w, _hand_tip(J, side), True)]
    return _bones_from(J, spec, rng)


def unnamed(J, rng):
    """Mixamo's layout with meaningless names (bone_00 ...): only the shape can map it."""
    bones = mixamo(J, rng, prefix="")
    rename = {b[0]: f"bone_{k:02d}" for k, b in enumerate(bones)}
    return [(rename[n], rename.get(p), h, t, r, d) for n, p, h, t, r, d in bones]


def daz(J, rng):
    """Daz/Poser style: a `hip` root below the hip joints, buttock bones, no toe bone, eyes."""
    low = 0.5 * (J[1] + J[2]) - [0, 0, 0.03]
    spec = [("hip", None, low, J[3], True), ("abdomen", "hip", 3, 6, True), ("chest", "abdomen", 6, 12, True),
            ("neck", "chest", 12, 15, True), ("head", "neck", 15, _head_top(J), True)]
    for s, x in (("l", 0.03), ("r", -0.03)):
        spec.append((f"{s}Eye", "head", J[15] + [x, -0.08, 0.06], J[15] + [x, -0.1, 0.06], True))
    for s, side in (("l", LEFT), ("r", RIGHT)):
        h, k, a, f = side["hip"], side["knee"], side["ankle"], side["foot"]
        c, sh, e, w = side["collar"], side["shoulder"], side["elbow"], side["wrist"]
        spec += [(f"{s}Buttock", "hip", low, h, True), (f"{s}Thigh", f"{s}Buttock", h, k, True),
                 (f"{s}Shin", f"{s}Thigh", k, a, True), (f"{s}Foot", f"{s}Shin", a, f, True),
                 (f"{s}Collar", "chest", c, sh, True), (f"{s}Shldr", f"{s}Collar", sh, e, True),
                 (f"{s}ForeArm", f"{s}Shldr", e, w, True), (f"{s}Hand", f"{s}ForeArm", w, _hand_tip(J, side), True)]
    return _bones_from(J, spec, rng)


SCHEMES = {"rigify": rigify, "mixamo": mixamo, "cc": cc, "unnamed": unnamed, "daz": daz}
# the bone that plays each SMPL joint in each scheme (the truth the mapping must find)
TRUTH = {
    "mixamo": {"pelvis": "mixamorig:Hips", "left_hip": "mixamorig:LeftUpLeg", "left_knee": "mixamorig:LeftLeg",
               "left_ankle": "mixamorig:LeftFoot", "left_shoulder": "mixamorig:LeftArm",
               "right_wrist": "mixamorig:RightHand", "head": "mixamorig:Head"},
    "rigify": {"pelvis": "DEF-spine", "left_hip": "DEF-thigh.L", "left_knee": "DEF-shin.L", "left_ankle": "DEF-foot.L",
               "left_shoulder": "DEF-upper_arm.L", "right_wrist": "DEF-hand.R", "head": "DEF-spine.006"},
    "cc": {"pelvis": "CC_Base_Hip", "left_hip": "CC_Base_L_Thigh", "left_knee": "CC_Base_L_Calf",
           "left_ankle": "CC_Base_L_Foot", "left_shoulder": "CC_Base_L_Upperarm", "right_wrist": "CC_Base_R_Hand",
           "head": "CC_Base_Head"},
}


def armature_rest(bones, matrix_world=None):
    """A core.scene.bone_map.ArmatureRest of these bones (Blender's bone matrix from head, tail
    and roll, via core.scene.bones.bone_matrix)."""
    from shapemove.core.scene.bone_map import ArmatureRest
    from shapemove.core.scene.bones import bone_matrix

    names = [b[0] for b in bones]
    parents = [names.index(b[1]) if b[1] else -1 for b in bones]
    heads = np.array([b[2] for b in bones])
    tails = np.array([b[3] for b in bones])
    rolls = np.array([b[4] for b in bones])
    rot = bone_matrix(tails - heads, rolls)
    return ArmatureRest(names, parents, heads, tails, rot, [b[5] for b in bones],
                        np.eye(4) if matrix_world is None else matrix_world)


# ---- source motions (numpy FK, no body model) ----

def _motion(rest24, local_rot, pelvis, fps=20.0):
    """A core.scene.motion_file.Motion: local rotations (T,24,3,3), pelvis positions (T,3), Y up."""
    from shapemove.core.body.skeleton import PARENTS
    from shapemove.core.geometry.fk import forward_kinematics
    from shapemove.core.geometry.rotations import matrix_to_axis_angle
    from shapemove.core.scene.motion_file import Motion, validate

    pos, _ = forward_kinematics(local_rot, rest24, PARENTS)
    transl = pelvis - rest24[0]
    joints = pos[:, :22] + transl[:, None]
    m = Motion(joints=joints.astype(np.float32), betas=np.zeros(10, np.float32),
               poses=matrix_to_axis_angle(local_rot).astype(np.float32), transl=transl.astype(np.float32),
               fps=fps, body_model="capsule-test")
    validate(m)
    return m


def wavy_motion(rest24, frames=40, seed=0):
    """Every joint turning smoothly (up to ~0.5 rad), the body walking towards +Z."""
    from shapemove.core.geometry.rotations import axis_angle_to_matrix

    rng = np.random.default_rng(seed)
    t = np.arange(frames)[:, None, None]
    aa = rng.normal(0, 0.35, (1, 24, 3)) * np.sin(0.25 * t + rng.uniform(0, 6, (1, 24, 3)))
    pelvis = rest24[0] + np.stack([0.01 * t[:, 0, 0], 0.03 * np.sin(0.3 * t[:, 0, 0]), 0.04 * t[:, 0, 0]], -1)
    return _motion(rest24, axis_angle_to_matrix(aa), pelvis)


def _rot_between(u, v):
    from shapemove.core.geometry.rotations import rotation_between
    return rotation_between(u, v)


def planted_motion(rest24, frames=60):
    """Both feet fixed on the floor (ankle and foot at their rest places, foot flat) while the
    pelvis bobs down up to 10 cm, sways and turns +-12 degrees and the upper body waves: the legs
    follow by exact two-bone IK."""
    from shapemove.core.geometry.rotations import axis_angle_to_matrix

    T = frames
    ph = np.linspace(0, 2 * np.pi, T)
    R = np.broadcast_to(np.eye(3), (T, 24, 3, 3)).copy()
    yaw = np.radians(12) * np.sin(ph)
    Rp = axis_angle_to_matrix(np.stack([0.05 * np.sin(2 * ph), yaw, np.zeros(T)], -1))
    pelvis = rest24[0] + np.stack([0.05 * np.sin(ph), -0.05 * (1 - np.cos(2 * ph)), 0.03 * np.sin(ph)], -1)
    R[:, 0] = Rp
    for j, amp in ((3, 0.15), (6, 0.1), (9, 0.1), (12, 0.2), (16, 0.5), (17, 0.4), (18, 0.6), (19, 0.5)):
        R[:, j] = axis_angle_to_matrix(np.stack([amp * np.sin(ph + j), 0.5 * amp * np.cos(ph), amp * np.sin(2 * ph)], -1))
    for hip, knee, ankle in ((1, 4, 7), (2, 5, 8)):
        Hp = pelvis + np.einsum("tij,j->ti", Rp, rest24[hip] - rest24[0])
        A = np.broadcast_to(rest24[ankle], (T, 3))
        a = np.linalg.norm(rest24[knee] - rest24[hip])
        b = np.linalg.norm(rest24[ankle] - rest24[knee])
        d = A - Hp
        c = np.linalg.norm(d, axis=-1, keepdims=True)
        u = d / c
        pole = np.array([0.0, 0.0, 1.0])  # knees bend forward (+Z)
        w = pole - (u @ pole)[:, None] * u
        w /= np.linalg.norm(w, axis=-1, keepdims=True)
        cos_a = np.clip((a * a + c ** 2 - b * b) / (2 * a * c), -1, 1)
        K = Hp + a * (cos_a * u + np.sqrt(1 - cos_a ** 2) * w)
        W_hip = _rot_between(np.einsum("tij,j->ti", Rp, rest24[knee] - rest24[hip]), K - Hp) @ Rp
        W_knee = _rot_between(np.einsum("tij,j->ti", W_hip, rest24[ankle] - rest24[knee]), A - K) @ W_hip
        R[:, hip] = np.swapaxes(Rp, -1, -2) @ W_hip
        R[:, knee] = np.swapaxes(W_hip, -1, -2) @ W_knee
        R[:, ankle] = np.swapaxes(W_knee, -1, -2)  # the foot stays at its world rest orientation
    return _motion(rest24, R, pelvis)


def reproportion(J, thigh=0.9, shin=1.15, arm=1.1, spine=0.95):
    """(22,3) Z-up joints with the bones scaled per body part (a rig of other proportions)."""
    from shapemove.core.body.skeleton import PARENTS

    par = PARENTS[:22]
    factor = np.ones(22)
    factor[[4, 5]] = thigh
    factor[[7, 8]] = shin
    factor[[18, 19, 20, 21]] = arm
    factor[[3, 6, 9, 12, 15]] = spine
    out = J.copy()
    for j in range(1, 22):
        out[j] = out[par[j]] + factor[j] * (J[j] - J[par[j]])
    return out
