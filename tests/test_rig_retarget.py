"""Baking a motion onto the user's own armature, Blender-free maths (core/scene/rig_retarget.py,
core/scene/bone_map.py): mapping by preset and by shape, rest-pose alignment (A-pose vs T-pose,
random bone rolls), scaled root motion, planted feet, presets on disk. The same bake inside real
Blender is checked in test_blender_rig_retarget.py."""
import json

import numpy as np
import pytest

from rig_builders import (SCHEMES, TRUTH, armature_rest, planted_motion, posed_joints, reproportion, wavy_motion,
                          z_up)
from shapemove.core.errors import ShapeMoveError
from shapemove.core.scene.bone_map import (REQUIRED, SMPL22, apply_preset, auto_map, builtin_presets, check_map,
                                           find_preset, load_preset, map_armature, save_preset)
from shapemove.core.scene.capsule_body import REST_JOINTS
from shapemove.core.scene.rig_retarget import retarget_to_armature, source_skeleton

MM = 1e-3


def _target(scheme, pose="T", scale=1.15, seed=0, joints=None):
    J = posed_joints(REST_JOINTS[:22], scale=scale, pose=pose) if joints is None else joints
    return armature_rest(SCHEMES[scheme](J, np.random.default_rng(seed)))


def test_source_skeleton_recovers_the_rest_joints():
    m = wavy_motion(REST_JOINTS, 30)
    P, G, rest = source_skeleton(m)
    np.testing.assert_allclose(rest, REST_JOINTS[:22], atol=1e-5)
    assert P.shape == (30, 22, 3) and G.shape == (30, 22, 3, 3)


@pytest.mark.parametrize("scheme", ["rigify", "mixamo", "cc"])
def test_presets_find_their_rigs(scheme):
    arm = _target(scheme)
    mapping, how = map_armature(arm)
    assert how.startswith("preset")
    assert len(mapping) == 22
    for joint, bone in TRUTH[scheme].items():
        assert mapping[joint] == bone


@pytest.mark.parametrize("scheme", ["mixamo", "cc", "rigify", "unnamed"])
def test_shape_match_finds_the_same_bones(scheme):
    """Without presets (the engine of mocap import): the key joints land on the right bones."""
    arm = _target(scheme, pose="A")
    mapping = auto_map(arm)
    # rig_builders.mixamo's bone order: 6 spine/head bones, then per side 8 limb and 9 finger bones
    truth = TRUTH.get(scheme) or {j: f"bone_{k:02d}" for j, k in (
        ("pelvis", 0), ("head", 5), ("left_hip", 6), ("left_knee", 7), ("left_ankle", 8), ("left_shoulder", 11),
        ("right_wrist", 30))}
    for joint, bone in truth.items():
        assert mapping.get(joint) == bone, (joint, mapping.get(joint), bone)
    assert all(j in mapping for j in REQUIRED)


@pytest.mark.parametrize("scheme,pose", [("rigify", "A"), ("mixamo", "T"), ("mixamo", "A"), ("cc", "A"),
                                         ("unnamed", "T")])
def test_bake_reproduces_the_scaled_source(scheme, pose):
    """A rig with the source's proportions x 1.15 in another rest pose with random rolls: every
    mapped joint follows the source's joints x 1.15 (plus one constant offset to the floor)."""
    m = wavy_motion(REST_JOINTS, 40)
    arm = _target(scheme, pose=pose, seed=3)
    mapping, _ = map_armature(arm)
    bake = retarget_to_armature(m, arm, mapping, plant_feet=False)
    assert abs(bake.scale - 1.15) < 1e-6 and abs(bake.heading) < 1e-6
    src = 1.15 * z_up(m.joints.astype(np.float64))
    mapped = [SMPL22.index(j) for j in mapping]
    diff = bake.joints[:, mapped] - src[:, mapped]
    offset = diff.reshape(-1, 3).mean(0)
    assert np.abs(offset[:2]).max() < 1e-6  # the armature stands at the origin: no horizontal shift
    assert np.abs(diff - offset).max() < 0.1 * MM
    np.testing.assert_allclose(bake.joints[:, mapped], bake.expected[:, mapped], atol=0.1 * MM)


def test_turned_and_moved_armature_gets_the_motion_in_its_own_frame():
    """An armature object turned 90 degrees about Z, moved and scaled: the motion starts where it
    stands and walks towards its own front."""
    m = wavy_motion(REST_JOINTS, 20)
    a = np.pi / 2
    Mw = np.eye(4)
    Mw[:3, :3] = 2.0 * np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    Mw[:3, 3] = [3.0, -1.0, 0.5]
    J = posed_joints(REST_JOINTS[:22], scale=0.5)
    base = _target("mixamo", joints=J)
    arm = armature_rest(SCHEMES["mixamo"](J, np.random.default_rng(0)), matrix_world=Mw)
    mapping, _ = map_armature(arm)
    bake = retarget_to_armature(m, arm, mapping, plant_feet=False)
    assert abs(bake.scale - 1.0) < 1e-6 and abs(abs(bake.heading) - np.pi / 2) < 1e-6
    src = z_up(m.joints.astype(np.float64)) @ Mw[:3, :3].T / 2.0
    d = bake.joints[:, :22] - src
    assert np.abs(d - d[0, 0]).max() < 0.1 * MM
    np.testing.assert_allclose(d[0, 0, :2], Mw[:2, 3], atol=1e-6)
    assert base.names == arm.names


def test_feet_stay_planted_on_a_rig_of_other_proportions():
    """Source feet still while the pelvis bobs, sways and turns; the target's thighs are 10%
    shorter, shins 15% longer: without IK its ankles would slide, with it they hold within 1 mm."""
    m = planted_motion(REST_JOINTS, 60)
    ank = m.joints[:, [7, 8]]
    assert np.ptp(ank, axis=0).max() < 1e-5  # the source really stands still
    J = reproportion(posed_joints(REST_JOINTS[:22], scale=1.0, pose="A"))
    J[:, 2] -= J[[10, 11], 2].min() - 0.02
    arm = _target("mixamo", joints=J, seed=5)
    mapping, _ = map_armature(arm)
    free = retarget_to_armature(m, arm, mapping, plant_feet=False)
    planted = retarget_to_armature(m, arm, mapping, plant_feet=True)
    assert planted.contacts[:, :2].all()  # both ankles in contact on every frame
    slide_free = np.ptp(free.joints[:, [7, 8]], axis=0).max()
    slide = np.ptp(planted.joints[:, [7, 8]], axis=0).max()
    assert slide_free > 5 * MM and slide < 1 * MM, (slide_free, slide)
    # the feet stand on the armature's floor (z = 0): ankles at their rest height above it
    np.testing.assert_allclose(planted.joints[:, 7, 2], J[7, 2], atol=2 * MM)
    # root height scaled to the legs: the scale is the leg-length ratio
    leg = lambda p: np.linalg.norm(p[1] - p[4]) + np.linalg.norm(p[4] - p[7])  # noqa: E731
    assert abs(planted.scale - leg(J) / leg(z_up(REST_JOINTS))) < 1e-6


def test_presets_round_trip_and_reject_bad_files(tmp_path):
    shipped = builtin_presets()
    assert {"rigify", "mixamo", "cc_iclone"} <= set(shipped)
    for p in shipped.values():
        assert set(p["bones"]) == set(SMPL22)
    arm = _target("cc")
    mapping, _ = map_armature(arm)
    path = save_preset(tmp_path / "mine.json", mapping, "My rig")
    loaded = load_preset(path)
    assert loaded["name"] == "My rig" and apply_preset(loaded, arm.names) == mapping
    assert find_preset("MIXAMO")["name"] == "Mixamo"
    # namespaces and case: mixamorig1:hips still matches the Mixamo preset
    names = [n.replace("mixamorig:", "mixamorig1:").lower() for n in _target("mixamo").names]
    assert apply_preset(shipped["mixamo"], names)["pelvis"] == "mixamorig1:hips"
    (tmp_path / "bad.json").write_text(json.dumps({"format": "shapemove-bone-map", "bones": {"tail": "x"}}))
    with pytest.raises(ShapeMoveError, match="not an SMPL body joint"):
        load_preset(tmp_path / "bad.json")
    (tmp_path / "junk.json").write_text("{not json")
    with pytest.raises(ShapeMoveError, match="cannot read"):
        load_preset(tmp_path / "junk.json")
    with pytest.raises(ShapeMoveError, match="unknown bone-map preset"):
        find_preset("blender-human")


def test_bad_maps_are_refused():
    arm = _target("mixamo")
    mapping, _ = map_armature(arm)
    with pytest.raises(ShapeMoveError, match="left_knee"):
        check_map({k: v for k, v in mapping.items() if k != "left_knee"}, arm.names)
    with pytest.raises(ShapeMoveError, match="no bones"):
        check_map({**mapping, "head": "Skull"}, arm.names)
    with pytest.raises(ShapeMoveError, match="plays both"):
        check_map({**mapping, "head": mapping["neck"]}, arm.names)


def test_fbx_style_armature_y_up_in_centimetres():
    """Mixamo FBX imports: bone data Y up in centimetres, the object turned +90 degrees about X
    and scaled 0.01. The bake works in world space, so the result is the same as for a Z-up rig."""
    m = wavy_motion(REST_JOINTS, 20)
    J = posed_joints(REST_JOINTS[:22], scale=1.0, pose="A")
    M = np.eye(4)
    M[:3, :3] = 0.01 * np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]])   # data Y-up cm -> world Z-up m
    inv = np.linalg.inv(M)
    bones = SCHEMES["mixamo"](J, np.random.default_rng(7))
    data = [(n, p, inv[:3, :3] @ h + inv[:3, 3], inv[:3, :3] @ t + inv[:3, 3], r, d) for n, p, h, t, r, d in bones]
    arm = armature_rest(data, matrix_world=M)
    mapping, how = map_armature(arm)
    bake = retarget_to_armature(m, arm, mapping, plant_feet=False)
    src = z_up(m.joints.astype(np.float64))
    d = bake.joints - src
    assert how == "preset Mixamo" and abs(bake.scale - 1) < 1e-6 and abs(bake.heading) < 1e-6
    assert np.abs(d - d.reshape(-1, 3).mean(0)).max() < 0.1 * MM
    # the keyed root offset is in the armature's own (centimetre) units
    assert np.abs(bake.root_offset).max() > 10


def test_daz_style_rig_with_fewer_spine_bones():
    """A `hip` root below the hip joints, two spine bones (abdomen, chest = spine2 + spine3), no toe
    bone: the legs hang from `hip` (the bone the bake moves), the spine bones take the joints their
    heads sit on, and the rig follows: legs exactly, the upper body (which lacks spine3) within 2.5 cm."""
    m = wavy_motion(REST_JOINTS, 40)
    arm = _target("daz", pose="A", scale=1.0, seed=3)
    mapping, how = map_armature(arm)
    assert how == "matched by shape"
    assert mapping["pelvis"] == "hip" and mapping["spine1"] == "abdomen" and mapping["spine2"] == "chest"
    assert "spine3" not in mapping and "left_foot" not in mapping and mapping["left_hip"] == "lThigh"
    bake = retarget_to_armature(m, arm, mapping, plant_feet=False)
    src = z_up(m.joints.astype(np.float64))
    d = bake.joints - src
    legs = [1, 2, 4, 5, 7, 8]
    off = d[:, legs].reshape(-1, 3).mean(0)
    assert np.abs(d[:, legs] - off).max() < 0.1 * MM
    upper = [SMPL22.index(j) for j in mapping if j not in ("pelvis",) and SMPL22.index(j) not in legs]
    assert np.abs(d[:, upper] - off).max() < 25 * MM
