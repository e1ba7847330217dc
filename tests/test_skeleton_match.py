"""Skeletons absent from rig_map's tables, mapped by their shape (core/io/skeleton_match.py):
renamed joints, prefixes, extra twist and finger bones, a CMU BVH with ASF names and root `hip`,
a Bip01 rig, Z-up and centimetres; each checked joint by joint against the SMPL skeleton it was
built on. Failures name the missing body part."""
import numpy as np
import pytest

from mocap_synth import SMPL_REST, bvh_text, mixamo_skeleton, still_motion
from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.mocap import load_smpl22
from shapemove.core.io.rig_map import detect_rig, find_rig, map_positions, mapping_matrix
from shapemove.core.io.skeleton_match import match_humanoid, side_hint

LIMBS = [1, 2, 4, 5, 7, 8, 10, 11, 12, 15, 16, 17, 18, 19, 20, 21]  # SMPL joints taken straight from the rig


class Builder:
    """A skeleton built joint by joint: add(name, parent, position)."""

    def __init__(self):
        self.names, self.parents, self.pos = [], [], []

    def add(self, name, parent, p):
        self.names.append(name)
        self.parents.append(-1 if parent is None else self.names.index(parent))
        self.pos.append(np.asarray(p, dtype=np.float64))
        return name

    def arrays(self):
        return list(self.names), np.array(self.parents), np.stack(self.pos)


def _end(b, parent, d=(0, 0, 0.02)):
    b.add(parent + "_End", parent, b.pos[b.names.index(parent)] + np.asarray(d))


def fancy_rig(prefix="Char_", side=lambda s: f"{s}_", fingers=True, twists=True):
    """SMPL_REST with prefixed names, upper-arm/forearm/thigh twist bones (in-chain and leaf),
    five three-joint fingers per hand, eyes and a jaw on the head, a root on the floor."""
    R = SMPL_REST
    b = Builder()
    b.add(prefix + "Root", None, [0, 0, 0])
    b.add(prefix + "Pelvis", prefix + "Root", R[0])
    b.add(prefix + "Waist", prefix + "Pelvis", R[3])
    b.add(prefix + "Chest", prefix + "Waist", R[6])
    b.add(prefix + "UpperChest", prefix + "Chest", R[9])
    b.add(prefix + "Neck", prefix + "UpperChest", R[12])
    b.add(prefix + "Head", prefix + "Neck", R[15])
    b.add(prefix + "HeadTop", prefix + "Head", R[15] + [0, 0.18, 0])
    for eye, x in (("EyeL", 0.03), ("EyeR", -0.03)):
        b.add(prefix + eye, prefix + "Head", R[15] + [x, 0.06, 0.08])
    b.add(prefix + "Jaw", prefix + "Head", R[15] + [0, 0.0, 0.03])
    b.add(prefix + "JawEnd", prefix + "Jaw", R[15] + [0, -0.04, 0.09])
    for s, sign, (hip, knee, ankle, toe, col, sh, el, wr) in (
            ("L", 1, (1, 4, 7, 10, 13, 16, 18, 20)), ("R", -1, (2, 5, 8, 11, 14, 17, 19, 21))):
        p = prefix + side(s)
        b.add(p + "Thigh", prefix + "Pelvis", R[hip])
        if twists:
            b.add(p + "ThighTwist", p + "Thigh", 0.5 * (R[hip] + R[knee]))
            b.add(p + "Calf", p + "ThighTwist", R[knee])
        else:
            b.add(p + "Calf", p + "Thigh", R[knee])
        b.add(p + "Foot", p + "Calf", R[ankle])
        b.add(p + "Toe", p + "Foot", R[toe])
        _end(b, p + "Toe", (0, 0, 0.05))
        b.add(p + "Clavicle", prefix + "UpperChest", R[col])
        b.add(p + "UpperArm", p + "Clavicle", R[sh])
        if twists:
            b.add(p + "UpperArmTwist", p + "UpperArm", 0.5 * (R[sh] + R[el]))  # leaf helper
            b.add(p + "Forearm", p + "UpperArm", R[el])
            b.add(p + "ForearmTwist", p + "Forearm", 0.5 * (R[el] + R[wr]))     # in-chain
            b.add(p + "Hand", p + "ForearmTwist", R[wr])
        else:
            b.add(p + "Forearm", p + "UpperArm", R[sh] * 0 + R[el])
            b.add(p + "Hand", p + "Forearm", R[wr])
        if fingers:
            for k, (f, dz) in enumerate((("Thumb", 0.03), ("Index", 0.02), ("Mid", 0.0), ("Ring", -0.02),
                                         ("Pinky", -0.04))):
                prev = p + "Hand"
                for n in range(1, 4):
                    x = R[wr, 0] + sign * (0.03 if f == "Thumb" else 0.08 + 0.03 * n)
                    pos = [x + sign * (0.025 * n if f == "Thumb" else 0), R[wr, 1] - 0.01, R[wr, 2] + dz + (
                        0.03 * n if f == "Thumb" else 0)]
                    prev = b.add(f"{p}{f}{n}", prev, pos)
    return b.arrays()


def _check_against_smpl(names, parents, rest, atol=1e-9, rig=None):
    rig = rig or match_humanoid(names, parents, rest)
    j22, _ = map_positions(names, rest[None], rig=rig)
    np.testing.assert_allclose(j22[0, LIMBS], SMPL_REST[LIMBS], atol=atol)
    return rig, j22[0]


def test_renamed_mixamo_without_any_name_hints_matches_the_table_mapping():
    """Joints named j00.. (left/right from the feet's forward direction): the same matrix as the
    Mixamo table rig gives for the real names."""
    names, parents, rest = mixamo_skeleton()
    b = Builder()
    for n, p, x in zip(names, parents, rest):
        b.add(n, None if p < 0 else names[p], x)
    for toe in ("mixamorig:LeftToeBase", "mixamorig:RightToeBase", "mixamorig:Head", "mixamorig:LeftHand",
                "mixamorig:RightHand"):
        _end(b, toe, (0, 0, 0.05) if "Toe" in toe else (0, 0.15, 0) if "Head" in toe else (0, 0, 0))
    names, parents, rest = b.arrays()
    rest[names.index("mixamorig:LeftHand_End")] += [0.18, 0, 0]
    rest[names.index("mixamorig:RightHand_End")] += [-0.18, 0, 0]
    order = np.random.default_rng(0).permutation(len(names))
    renamed = [f"j{int(k):02d}" for k in np.argsort(order)]
    assert find_rig(renamed) is None
    rig = detect_rig(renamed, parents, rest)
    W_auto = mapping_matrix(rig, renamed, rest[None])
    W_table = mapping_matrix(detect_rig(names), names, rest[None])
    np.testing.assert_allclose(W_auto, W_table, atol=1e-12)
    assert rig.rules["left_hip"] == renamed[names.index("mixamorig:LeftUpLeg")]
    assert rig.rules["right_wrist"] == renamed[names.index("mixamorig:RightHand")]


@pytest.mark.parametrize("side", [lambda s: f"{s}_", lambda s: f"{'Left' if s == 'L' else 'Right'}",
                                  lambda s: s.lower()])
def test_prefixed_rig_with_twist_and_finger_bones(side):
    names, parents, rest = fancy_rig(side=side)
    assert find_rig(names) is None
    rig, j22 = _check_against_smpl(names, parents, rest)
    assert rig.rules["left_knee"] == "Char_" + side("L") + "Calf"   # not the thigh's twist bone
    assert rig.rules["left_elbow"] == "Char_" + side("L") + "Forearm"
    assert rig.rules["left_wrist"] == "Char_" + side("L") + "Hand"
    assert rig.rules["left_collar"] == "Char_" + side("L") + "Clavicle"
    assert rig.rules["head"] == "Char_Head" and rig.rules["neck"] == "Char_Neck"
    assert rig.chain == ("Char_Pelvis", "Char_Waist", "Char_Chest", "Char_UpperChest", "Char_Neck")
    np.testing.assert_allclose(j22[13], SMPL_REST[13], atol=1e-9)


def test_left_right_from_geometry_when_names_say_nothing():
    """Mirror the rig's X (subject's left <-> right) without renaming: the names now lie, so use a
    rig whose names carry no side: left/right must follow the geometry."""
    names, parents, rest = fancy_rig(side=lambda s: {"L": "A_", "R": "B_"}[s])
    rig, _ = _check_against_smpl(names, parents, rest)
    assert rig.rules["left_hip"] == "Char_A_Thigh"
    mirrored = rest * [-1, 1, 1]
    rig2 = match_humanoid(names, parents, mirrored)
    assert rig2.rules["left_hip"] == "Char_B_Thigh"


def test_zup_centimetres_rig_matches_the_same_joints():
    names, parents, rest = fancy_rig()
    zup = 100 * rest @ np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]).T
    assert match_humanoid(names, parents, zup).rules == match_humanoid(names, parents, rest).rules


def cmu_hip_rig():
    """A CMU BVH with ASF names and root `hip` (each joint at its bone's start, clavicles on the
    mid-line, hipjoint at the root), as the issue reports it."""
    R = SMPL_REST
    b = Builder()
    mid = 0.5 * (R[1] + R[2])
    b.add("hip", None, mid)
    b.add("lowerback", "hip", mid + [0, 0.05, 0])
    b.add("upperback", "lowerback", R[6])
    b.add("thorax", "upperback", R[9])
    b.add("lowerneck", "thorax", R[12] - [0, 0.04, 0])
    b.add("upperneck", "lowerneck", R[12])
    b.add("head", "upperneck", R[15])
    _end(b, "head", (0, 0.15, 0))
    for s, (hip, knee, ankle, toe, sh, el, wr) in (("l", (1, 4, 7, 10, 16, 18, 20)), ("r", (2, 5, 8, 11, 17, 19, 21))):
        b.add(s + "hipjoint", "hip", mid)
        b.add(s + "femur", s + "hipjoint", R[hip])
        b.add(s + "tibia", s + "femur", R[knee])
        b.add(s + "foot", s + "tibia", R[ankle])
        b.add(s + "toes", s + "foot", R[toe])
        _end(b, s + "toes", (0, 0, 0.04))
        b.add(s + "clavicle", "thorax", R[9] + [0, 0.1, 0])
        b.add(s + "humerus", s + "clavicle", R[sh])
        b.add(s + "radius", s + "humerus", R[el])
        b.add(s + "wrist", s + "radius", R[wr])
        b.add(s + "hand", s + "wrist", R[wr] + [0.06 * (1 if s == "l" else -1), 0, 0])
        b.add(s + "fingers", s + "hand", R[wr] + [0.1 * (1 if s == "l" else -1), 0, 0])
        _end(b, s + "fingers", (0.04 * (1 if s == "l" else -1), 0, 0))
        b.add(s + "thumb", s + "hand", R[wr] + [0.07 * (1 if s == "l" else -1), 0, 0.04])
        _end(b, s + "thumb", (0.02 * (1 if s == "l" else -1), 0, 0.02))
    return b.arrays()


def test_cmu_bvh_with_asf_names_and_root_hip():
    names, parents, rest = cmu_hip_rig()
    with pytest.raises(ShapeMoveError):
        detect_rig(names)            # the tables expect `root`
    rig, j22 = _check_against_smpl(names, parents, rest)
    assert rig.rules["left_hip"] == "lfemur" and rig.rules["left_foot"] == "ltoes"
    assert rig.rules["left_wrist"] == "lwrist" and rig.rules["neck"] == "upperneck"
    assert rig.rules["left_collar"][:3] == ("lerp", "lclavicle", "lhumerus")  # clavicle on the mid-line
    # the collar lands 45% of the way out to the shoulder, like the cmu_asf table rig
    assert abs(j22[13, 0] - 0.45 * SMPL_REST[16, 0]) < 2e-3
    # the same skeleton with its root called `root` maps through the table: same limbs
    table = ["root" if n == "hip" else n for n in names]
    assert detect_rig(table).name == "cmu_asf"
    j_table, _ = map_positions(table, rest[None])
    np.testing.assert_allclose(j22[LIMBS], j_table[0, LIMBS], atol=1e-9)
    np.testing.assert_allclose(j22[[0, 3, 6, 9]], j_table[0, [0, 3, 6, 9]], atol=0.02)


def bip01_rig():
    """3ds Max Biped naming: thighs hang from Bip01 Spine, clavicles from Bip01 Neck, Nub ends."""
    R = SMPL_REST
    b = Builder()
    b.add("Bip01", None, [0, R[0, 1], 0])
    b.add("Bip01 Pelvis", "Bip01", R[0])
    b.add("Bip01 Spine", "Bip01 Pelvis", R[0] + [0, 0.02, 0])
    b.add("Bip01 Spine1", "Bip01 Spine", R[3])
    b.add("Bip01 Spine2", "Bip01 Spine1", R[6])
    b.add("Bip01 Spine3", "Bip01 Spine2", R[9])
    b.add("Bip01 Neck", "Bip01 Spine3", R[12])
    b.add("Bip01 Head", "Bip01 Neck", R[15])
    b.add("Bip01 HeadNub", "Bip01 Head", R[15] + [0, 0.17, 0])
    for s, (hip, knee, ankle, toe, col, sh, el, wr) in (
            ("L", (1, 4, 7, 10, 13, 16, 18, 20)), ("R", (2, 5, 8, 11, 14, 17, 19, 21))):
        p = f"Bip01 {s} "
        b.add(p + "Thigh", "Bip01 Spine", R[hip])
        b.add(p + "Calf", p + "Thigh", R[knee])
        b.add(p + "Foot", p + "Calf", R[ankle])
        b.add(p + "Toe0", p + "Foot", R[toe])
        b.add(p + "Toe0Nub", p + "Toe0", R[toe] + [0, 0, 0.05])
        b.add(p + "Clavicle", "Bip01 Neck", R[col])
        b.add(p + "UpperArm", p + "Clavicle", R[sh])
        b.add(p + "Forearm", p + "UpperArm", R[el])
        b.add(p + "Hand", p + "Forearm", R[wr])
        b.add(p + "Finger0", p + "Hand", R[wr] + [0.05 * (1 if s == "L" else -1), 0, 0.03])
        b.add(p + "Finger0Nub", p + "Finger0", R[wr] + [0.08 * (1 if s == "L" else -1), 0, 0.05])
        b.add(p + "Finger2", p + "Hand", R[wr] + [0.09 * (1 if s == "L" else -1), 0, 0])
        b.add(p + "Finger2Nub", p + "Finger2", R[wr] + [0.17 * (1 if s == "L" else -1), 0, 0])
    return b.arrays()


def test_bip01_rig():
    names, parents, rest = bip01_rig()
    rig, _ = _check_against_smpl(names, parents, rest)
    assert rig.rules["left_hip"] == "Bip01 L Thigh" and rig.rules["right_ankle"] == "Bip01 R Foot"
    assert rig.rules["head"] == "Bip01 Head" and rig.rules["neck"] == "Bip01 Neck"
    assert rig.chain[0] == "Bip01 Spine"


def test_bvh_file_of_an_unknown_rig_loads(tmp_path):
    """The whole import path: a Bip01 BVH in centimetres, Z up, maps joint by joint."""
    names, parents, rest = bip01_rig()
    zup_cm = 100 * rest @ np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]).T
    path = tmp_path / "bip.bvh"
    path.write_text(bvh_text(names, parents, zup_cm, still_motion(zup_cm[0], len(names), 30)))
    m = load_smpl22(path, drop_tpose=False)
    assert m.rig == "auto"
    np.testing.assert_allclose(m.joints[0, LIMBS], SMPL_REST[LIMBS], atol=1e-5)


def test_side_hints():
    assert side_hint("mixamorig:LeftArm") == 1 and side_hint("DEF-thigh.R") == -1
    assert side_hint("Bip01 L Thigh") == 1 and side_hint("CC_Base_R_Hand") == -1
    assert side_hint("lThigh") == 1 and side_hint("rShldr") == -1
    assert side_hint("lowerback") == 0 and side_hint("Spine") == 0


def test_errors_name_the_missing_part():
    names, parents, rest = fancy_rig(fingers=False)
    # an arm cut off at the shoulder: four ends
    drop = {n for n in names if n.startswith("Char_L_") and any(k in n for k in ("Arm", "Forearm", "Hand"))}
    keep = [i for i, n in enumerate(names) if n not in drop]
    idx = {old: new for new, old in enumerate(keep)}
    sub_parents = [idx[parents[i]] if parents[i] >= 0 else -1 for i in keep]
    with pytest.raises(ShapeMoveError, match="two feet, two hands and a head"):
        detect_rig([names[i] for i in keep], sub_parents, rest[keep])
    # legs without toes: the foot joint has nowhere to go
    drop = {n for n in names if "Toe" in n}
    keep = [i for i, n in enumerate(names) if n not in drop]
    idx = {old: new for new, old in enumerate(keep)}
    sub_parents = [idx[parents[i]] if parents[i] >= 0 else -1 for i in keep]
    with pytest.raises(ShapeMoveError, match="no toe"):
        detect_rig([names[i] for i in keep], sub_parents, rest[keep])


REAL_CLIPS = ["bandai/dataset-1/data/dataset-1_walk_active_001.bvh", "cmu/bvh/02/02_01.bvh",
              "cmu/asfamc/02/02_01.amc", "hdm05/bd/HDM_bd_kickLFront1Reps_001_120.amc"]


@pytest.mark.parametrize("rel", REAL_CLIPS)
def test_real_rigs_match_their_table_by_shape(mocap_root, rel):
    """The archives' own skeletons (Bandai, Daz-style CMU BVH, CMU and HDM05 ASF), matched by shape
    with their names and again with every joint renamed (End Sites keep the readers' `<joint>_End`):
    the 22 SMPL joints agree with the hand-made table mapping within 1 mm over the clip's first
    200 frames. Known difference: renamed ASF rigs put the wrist at `lhand` (where the fingers
    fork), 8-10 cm past the table's `lwrist`. Compared without the layout's upper-body anchoring
    (``rig_map.ANCHORED``: only table rigs known to need it get it)."""
    from shapemove.core.geometry.fk import joints_from_offsets
    from shapemove.core.io.mocap import load_mocap
    from shapemove.core.io.rig_map import DEFAULT_LAYOUT, BodyLayout, pose_candidates

    layout = BodyLayout(spine=DEFAULT_LAYOUT.spine, hip_width=DEFAULT_LAYOUT.hip_width)

    m = load_mocap(mocap_root / rel)
    pos = m.positions[:200]
    table = detect_rig(m.names)
    want = mapping_matrix(table, m.names, pos, layout) @ pos
    poses = pose_candidates(joints_from_offsets(m.offsets, m.parents), m.positions)
    short = [f"j{k:03d}" for k in range(len(m.names))]
    renamed = [short[p] + "_End" if n.endswith("_End") else short[k] for k, (n, p) in enumerate(zip(m.names, m.parents))]
    for names in (m.names, renamed):
        rig = match_humanoid(names, m.parents, poses)
        got = mapping_matrix(rig, names, pos, layout) @ pos
        err = np.linalg.norm(got - want, axis=-1).max(0)
        skip = [20, 21] if names is renamed and rel.endswith(".amc") else []
        assert np.delete(err, skip).max() < 1e-3, (rel, names is renamed, np.round(err * 100, 1))


def test_bvh_of_a_half_body_says_what_is_missing(tmp_path):
    """An upper body only (no legs): the import error says a humanoid needs feet, not a joint list."""
    names, parents, rest = fancy_rig(fingers=False, twists=False)
    keep = [i for i, n in enumerate(names) if not any(k in n for k in ("Thigh", "Calf", "Foot", "Toe"))]
    idx = {old: new for new, old in enumerate(keep)}
    sub = [names[i] for i in keep]
    par = [idx[parents[i]] if parents[i] >= 0 else -1 for i in keep]
    path = tmp_path / "half.bvh"
    path.write_text(bvh_text(sub, par, 100 * rest[keep], still_motion(100 * rest[keep][0], len(sub), 10)))
    with pytest.raises(ShapeMoveError, match=r"unknown skeleton .*two feet, two hands and a head"):
        load_smpl22(path)


@pytest.mark.parametrize("shape", ["chain", "star", "random"])
def test_hostile_skeleton_shapes_fail_fast(shape):
    """2000-joint chains, stars and random trees: an answer in well under a second (the pruning is
    O(J log J)); more joints than MAX_JOINTS are refused unread."""
    import time

    from shapemove.core.io.skeleton_match import MAX_JOINTS

    rng = np.random.default_rng(0)
    J = 2000
    parents = {"chain": np.arange(-1, J - 1), "star": np.r_[-1, np.zeros(J - 1, int)],
               "random": np.r_[-1, [rng.integers(0, j) for j in range(1, J)]]}[shape]
    t = time.perf_counter()
    try:  # chains and stars are refused; a random tree may happen to pass every humanoid check
        match_humanoid([f"j{k}" for k in range(J)], parents, rng.normal(size=(J, 3)))
        assert shape == "random"
    except ShapeMoveError:
        pass
    assert time.perf_counter() - t < 1.0
    with pytest.raises(ShapeMoveError, match="more than the"):
        match_humanoid([f"j{k}" for k in range(MAX_JOINTS + 1)], np.arange(-1, MAX_JOINTS), np.zeros((MAX_JOINTS + 1, 3)))
