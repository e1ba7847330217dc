"""Rig mapping to the 22 SMPL body joints: direct joints, spine-chain interpolation and hip width
in the body's layout (OpenBody's by default), left/right, namespaces, unknown rigs."""
import numpy as np
import pytest

from mocap_synth import MIXAMO, SMPL_REST, mixamo_skeleton
from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.rig_map import (DEFAULT_LAYOUT, OPENBODY_LAYOUT, SMPL_LAYOUT, SPINE_FRACTIONS, BodyLayout, body_layout,
                                       detect_rig, map_positions, normalize)


def _chain_point(points, frac):
    seg = np.linalg.norm(np.diff(points, axis=0), axis=-1)
    s = frac * seg.sum()
    cum = np.concatenate([[0], np.cumsum(seg)])
    k = min(np.searchsorted(cum, s, side="right") - 1, len(seg) - 1)
    t = (s - cum[k]) / seg[k]
    return (1 - t) * points[k] + t * points[k + 1]


def test_mixamo_direct_and_chain_joints():
    names, parents, rest = mixamo_skeleton()
    plain, _ = map_positions(names, rest[None])  # DEFAULT_LAYOUT: OpenBody's spine, the rig's hips
    j22, rig = map_positions(names, rest[None], layout=OPENBODY_LAYOUT)
    assert rig.name == "mixamo" and DEFAULT_LAYOUT.spine == OPENBODY_LAYOUT.spine
    np.testing.assert_allclose(plain[0, [1, 2]], SMPL_REST[[1, 2]], atol=1e-12)
    np.testing.assert_allclose(np.delete(plain[0], [1, 2], 0), np.delete(j22[0], [1, 2], 0), atol=1e-12)
    j22 = j22[0]
    # every limb joint, the neck and the head come straight from the source
    for i in [4, 5, 7, 8, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21]:
        np.testing.assert_allclose(j22[i], SMPL_REST[i], atol=1e-12)
    # pelvis/spine1/2/3 lie on the mid-hips -> Hips -> Spine -> Spine1 -> Spine2 -> Neck polyline
    mid = (SMPL_REST[1] + SMPL_REST[2]) / 2
    chain = np.stack([mid, SMPL_REST[0], SMPL_REST[3], SMPL_REST[6], SMPL_REST[9], SMPL_REST[12]])
    for name, idx in (("pelvis", 0), ("spine1", 3), ("spine2", 6), ("spine3", 9)):
        np.testing.assert_allclose(j22[idx], _chain_point(chain, SPINE_FRACTIONS[name]), atol=1e-12)
    # OpenBody's pelvis sits ~2 cm above the mid-hips point; its hips are spread about that point
    # to 0.138 x leg length each side (SMPL_REST: leg 0.815 m, hips 0.07 m out -> 0.1125 m)
    assert abs(j22[0, 0]) < 1e-9 and 0.01 < j22[0, 1] - mid[1] < 0.03
    leg = np.linalg.norm(SMPL_REST[4] - SMPL_REST[1]) + np.linalg.norm(SMPL_REST[7] - SMPL_REST[4])
    for side, sign in ((1, 1), (2, -1)):
        np.testing.assert_allclose(j22[side], mid + sign * np.array([OPENBODY_LAYOUT.hip_width * leg, 0, 0]),
                                   atol=1e-12)


def test_legacy_smpl_layout():
    """SMPL_LAYOUT: the rig's own hip joints, the pelvis ~9 cm above them (neutral SMPL)."""
    names, parents, rest = mixamo_skeleton()
    j22, _ = map_positions(names, rest[None], layout=SMPL_LAYOUT)
    np.testing.assert_allclose(j22[0, [1, 2]], SMPL_REST[[1, 2]], atol=1e-12)
    assert abs(j22[0, 0, 0]) < 1e-9 and 0.05 < j22[0, 0, 1] - SMPL_REST[1, 1] < 0.13


def test_openbody_layout_matches_the_asset(openbody):
    """The constants are OpenBody's own rest joints, and mapping a rig that stands on OpenBody's
    joints gives OpenBody's pelvis, spine and hips back."""
    rest = openbody.rest_joints()[0].double().numpy()
    measured = body_layout(rest)
    np.testing.assert_allclose(OPENBODY_LAYOUT.spine, measured.spine, atol=1e-3)
    assert abs(OPENBODY_LAYOUT.hip_width - measured.hip_width) < 1e-3
    names, _, _ = mixamo_skeleton()
    src = np.stack([rest[MIXAMO[n.split(":")[-1]]] for n in names])
    j22, _ = map_positions(names, src[None], layout=measured)
    np.testing.assert_allclose(j22[0], rest[:22], atol=1e-9)
    # the rounded constants: within a millimetre
    j22, _ = map_positions(names, src[None], layout=OPENBODY_LAYOUT)
    np.testing.assert_allclose(j22[0], rest[:22], atol=1e-3)


def test_hip_width_scales_with_the_leg_not_the_unit():
    names, parents, rest = mixamo_skeleton()
    a, _ = map_positions(names, rest[None], layout=OPENBODY_LAYOUT)
    b, _ = map_positions(names, 100 * rest[None], layout=OPENBODY_LAYOUT)  # centimetres: the same skeleton
    np.testing.assert_allclose(100 * a, b, atol=1e-9)
    wide = BodyLayout(spine=OPENBODY_LAYOUT.spine, hip_width=0.2)
    c, _ = map_positions(names, rest[None], layout=wide)
    assert np.linalg.norm(c[0, 1] - c[0, 2]) > np.linalg.norm(a[0, 1] - a[0, 2]) + 0.09


def test_mapping_is_linear_per_frame():
    """Mapping a moved skeleton equals moving the mapped skeleton (rigid motion commutes)."""
    names, parents, rest = mixamo_skeleton()
    a = np.radians(40)
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    moved = rest @ R.T + np.array([1.0, 0.2, -3.0])
    both, _ = map_positions(names, np.stack([rest, moved]))
    np.testing.assert_allclose(both[1], both[0] @ R.T + np.array([1.0, 0.2, -3.0]), atol=1e-12)


BANDAI_LIMBS = ("Shoulder", "UpperArm", "LowerArm", "Hand", "UpperLeg", "LowerLeg", "Foot", "Toes")
ASF_LIMBS = ("hipjoint", "femur", "tibia", "foot", "toes", "clavicle", "humerus", "radius", "wrist")
CGSPEED_LIMBS = ("UpLeg", "Leg", "Foot", "ToeBase", "Shoulder", "Arm", "ForeArm", "Hand")
DAZ_LIMBS = ("Collar", "Shldr", "ForeArm", "Hand", "Buttock", "Thigh", "Shin", "Foot", "Foot_End")


@pytest.mark.parametrize("names,rig", [
    (["joint_Root", "Hips", "Spine", "Chest", "Neck", "Head"]
     + [f"{b}_{s}" for s in "LR" for b in BANDAI_LIMBS],
     "bandai"),
    (["root", "lowerback", "upperback", "thorax", "lowerneck", "upperneck", "head"]
     + [f"{s}{b}" for s in "lr" for b in ASF_LIMBS],
     "cmu_asf"),
    (["Hips", "LowerBack", "Spine", "Spine1", "Neck", "Neck1", "Head"]
     + [f"{s}{b}" for s in ("Left", "Right") for b in CGSPEED_LIMBS],
     "cmu_cgspeed"),
    (["hip", "abdomen", "chest", "neck", "head"]
     + [f"{s}{b}" for s in "lr" for b in DAZ_LIMBS],
     "daz"),
])
def test_known_rigs_detected(names, rig):
    assert detect_rig(names).name == rig


def test_left_right_from_names():
    """Swapping the source's Left/Right joints swaps SMPL's left/right joints."""
    names, parents, rest = mixamo_skeleton(prefix="")
    swapped = [n.replace("Left", "TMP").replace("Right", "Left").replace("TMP", "Right") for n in names]
    a, _ = map_positions(names, rest[None])
    b, _ = map_positions(swapped, rest[None])
    for left, right in ((1, 2), (4, 5), (7, 8), (10, 11), (13, 14), (16, 17), (18, 19), (20, 21)):
        np.testing.assert_allclose(a[0, left], b[0, right], atol=1e-12)
    assert a[0, 1, 0] > 0 and a[0, 16, 0] > 0  # SMPL left at +X


def test_cmu_clavicle_interpolated():
    names = ["root", "lowerback", "upperback", "thorax", "lowerneck", "upperneck", "head"] + [
        f"{s}{b}" for s in "lr" for b in ASF_LIMBS]
    pos = np.random.default_rng(0).normal(size=(3, len(names), 3))
    j22, _ = map_positions(names, pos)
    lc, lh = names.index("lclavicle"), names.index("lhumerus")
    np.testing.assert_allclose(j22[:, 13], 0.55 * pos[:, lc] + 0.45 * pos[:, lh], atol=1e-12)
    np.testing.assert_allclose(j22[:, 10], pos[:, names.index("ltoes")], atol=1e-12)


def test_namespace_and_case():
    assert normalize("mixamorig:LeftArm") == "leftarm"
    assert normalize("Character1|Hips") == "hips"
    names, _, _ = mixamo_skeleton(prefix="mixamorig1:")
    assert detect_rig([n.upper() for n in names]).name == "mixamo"


def test_unknown_rig_lists_missing_smpl_joints():
    names, _, _ = mixamo_skeleton()
    partial = [n for n in names if "LeftHand" not in n and "RightFoot" not in n]
    with pytest.raises(ShapeMoveError) as err:
        detect_rig(partial)
    msg = str(err.value)
    assert "left_wrist" in msg and "right_ankle" in msg and "mixamo" in msg
    assert "left_elbow" not in msg
    with pytest.raises(ShapeMoveError, match="pelvis"):
        detect_rig(["a", "b", "c"])


BANDAI = {"Hips": 0, "Spine": 3, "Chest": 6, "Neck": 12, "Head": 15, "UpperLeg_L": 1, "LowerLeg_L": 4,
          "Foot_L": 7, "Toes_L": 10, "UpperLeg_R": 2, "LowerLeg_R": 5, "Foot_R": 8, "Toes_R": 11,
          "Shoulder_L": 13, "UpperArm_L": 16, "LowerArm_L": 18, "Hand_L": 20,
          "Shoulder_R": 14, "UpperArm_R": 17, "LowerArm_R": 19, "Hand_R": 21}


def test_anchored_rig_gets_the_bodys_neck_head_and_collars(openbody):
    """A Bandai rig standing on OpenBody's joints, but with its Neck 3 cm low, its Head 4 cm long and
    its clavicle roots on the mid-line (how loosely such rigs place them): the mapped neck, head and
    collars land near OpenBody's (within 1.5-2 cm: each stays on its rig bone's line, the clavicle
    root moved to the mid-line tilts that line), not on the rig's 3-6 cm off; the limbs stay the rig's joints exactly; without the
    ``upper`` layout the rig's own joints come back."""
    from shapemove.core.io.rig_map import ANCHORED

    assert "bandai" in ANCHORED and "cmu_asf" not in ANCHORED
    rest = openbody.rest_joints()[0].double().numpy()
    measured = body_layout(rest)
    np.testing.assert_allclose(OPENBODY_LAYOUT.upper, measured.upper, atol=1e-3)
    names = list(BANDAI)
    src = np.stack([rest[BANDAI[n]] for n in names])
    up = rest[15] - rest[12]
    src[names.index("Neck")] -= 0.3 * up                      # ~3 cm low
    src[names.index("Head")] += 0.4 * up                      # ~4 cm past OpenBody's head joint
    src[names.index("Shoulder_L"), 0] = src[names.index("Shoulder_R"), 0] = 0.0
    j22, rig = map_positions(names, src[None], layout=measured)
    assert rig.name == "bandai"
    err = np.linalg.norm(j22[0] - rest[:22], axis=-1)
    assert err[12] < 0.015 and err[13] < 0.015 and err[14] < 0.015 and err[15] < 0.02, np.round(err * 100, 2)
    for i in [1, 2, 4, 5, 7, 8, 10, 11, 16, 17, 18, 19, 20, 21]:
        np.testing.assert_allclose(j22[0, i], rest[i], atol=1e-12)
    plain, _ = map_positions(names, src[None], layout=BodyLayout(spine=measured.spine))
    np.testing.assert_allclose(plain[0, [12, 13, 15]], src[[names.index(n) for n in ("Neck", "Shoulder_L", "Head")]],
                               atol=1e-12)
    # scale-free: the same skeleton in centimetres maps to the same joints x 100
    cm, _ = map_positions(names, 100 * src[None], layout=measured)
    np.testing.assert_allclose(cm, 100 * j22, atol=1e-9)
