"""BVH reader: hand-derived FK, channel orders, position channels, unit/up detection, and real
Bandai and CMU files (units, heights, bone lengths, left/right, resampling, T-pose lead-in)."""
import numpy as np
import pytest

from mocap_synth import bvh_text, mixamo_skeleton, still_motion
from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.bvh import load_bvh
from shapemove.core.geometry.fk import forward_kinematics, joints_from_offsets
from shapemove.core.io.mocap import load_mocap, load_smpl22
from shapemove.core.io.rig_map import map_positions
from shapemove.core.io.tpose import is_tpose

TINY = """HIERARCHY
ROOT hip
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT thigh
  {
    OFFSET 10 0 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 -40 0
    }
  }
  JOINT slider
  {
    OFFSET 0 5 0
    CHANNELS 3 Xposition Yposition Zposition
  }
}
MOTION
Frames: 3
Frame Time: 0.5
1 2 3 0 0 0   0 0 0    0 5 0
0 0 0 90 0 0  90 0 0   0 5 0
0 0 0 0 0 0   90 90 0  7 8 9
"""


def test_tiny_bvh_hand_derived(tmp_path):
    p = tmp_path / "tiny.bvh"
    p.write_text(TINY)
    m = load_bvh(p, unit="m", up_axis="Y")
    assert m.names == ["hip", "thigh", "thigh_End", "slider"]
    assert list(m.parents) == [-1, 0, 1, 0]
    assert m.fps == 2.0 and m.num_frames == 3
    P = m.positions
    # frame 0: translation only
    np.testing.assert_allclose(P[0], [[1, 2, 3], [11, 2, 3], [11, -38, 3], [1, 7, 3]], atol=1e-12)
    # frame 1: root Rz(90) takes +X to +Y; thigh Rx(90) takes -Y to -Z
    np.testing.assert_allclose(P[1, 1], [0, 10, 0], atol=1e-12)
    np.testing.assert_allclose(P[1, 2], [0, 10, -40], atol=1e-12)
    # frame 2: channels 'X Y Z' compose as Rx(90) @ Ry(90): (0,-40,0) -> (0,0,-40) (Ry @ Rx would give (-40,0,0))
    np.testing.assert_allclose(P[2, 2] - P[2, 1], [0, 0, -40], atol=1e-12)
    # position channels replace the offset
    np.testing.assert_allclose(P[2, 3], [7, 8, 9], atol=1e-12)
    # local rotations reproduce the positions
    R1 = m.rotations[1]
    np.testing.assert_allclose(P[1, 2], P[1, 1] + R1[0] @ R1[1] @ m.offsets[2], atol=1e-12)


def test_tiny_bvh_units_override(tmp_path):
    p = tmp_path / "tiny.bvh"
    p.write_text(TINY)
    m = load_bvh(p, unit="cm", up_axis="Y")
    np.testing.assert_allclose(m.positions[0, 2], [0.11, -0.38, 0.03], atol=1e-12)
    assert m.scale == 0.01
    with pytest.raises(ShapeMoveError, match="unknown unit"):
        load_bvh(p, unit="furlong")


@pytest.mark.parametrize("unit,scale", [("inch", 0.0254), ("cm", 0.01), ("m", 1.0), ("mm", 0.001)])
@pytest.mark.parametrize("up", ["Y", "Z"])
def test_unit_and_up_axis_detected(tmp_path, unit, scale, up):
    """A Mixamo humanoid written in several units and up axes reads back as the same metres, Y up."""
    names, parents, rest = mixamo_skeleton()
    to_file = np.eye(3) if up == "Y" else np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]])  # Y-up -> Z-up
    rest_file = rest @ to_file.T / scale
    motion = still_motion(rest_file[0], len(names), 4)
    motion[:, 0] += np.arange(4) * 0.5 / scale  # walk along +X: 0.5 m a frame
    motion[1:, 3:] = np.random.default_rng(0).uniform(-20, 20, size=(3, motion.shape[1] - 3))  # degrees
    p = tmp_path / "h.bvh"
    p.write_text(bvh_text(names, parents, rest_file, motion, frame_time=0.04))
    m = load_mocap(p)
    assert (m.unit, m.up_axis) == (unit, up)
    assert m.fps == pytest.approx(25.0)
    np.testing.assert_allclose(m.positions[0][[m.index(n) for n in names]], rest, atol=2e-6)
    np.testing.assert_allclose(m.positions[3, 0] - m.positions[0, 0], [1.5, 0, 0], atol=2e-6)
    j22, _ = map_positions(m.names, m.positions)
    assert j22[0, 1, 0] > 0  # left hip still at +X: the up-axis fix is a rotation, not a mirror
    # offsets and local rotations were converted consistently with the positions
    local = np.broadcast_to(m.offsets, m.positions.shape).copy()
    local[:, 0] = m.positions[:, 0]
    posed, _ = forward_kinematics(m.rotations, joints_from_offsets(local, m.parents), m.parents)
    np.testing.assert_allclose(posed, m.positions, atol=1e-9)


def test_rejects_missing_motion(tmp_path):
    p = tmp_path / "bad.bvh"
    p.write_text(TINY.split("MOTION")[0])
    with pytest.raises(ShapeMoveError, match="MOTION"):
        load_bvh(p)
    p.write_text(TINY.replace("0 0 0 0 0 0   90 90 0  7 8 9\n", ""))
    with pytest.raises(ShapeMoveError, match="truncated"):
        load_bvh(p, unit="m", up_axis="Y")


# ---------------------------------------------------------------------------- real files
def _facing_speed(j):
    """Per-frame horizontal root velocity along the body's facing (cross(left - right, up))."""
    across = j[:, 1] - j[:, 2]
    fwd = np.cross(across, [0.0, 1.0, 0.0])
    fwd /= np.linalg.norm(fwd, axis=-1, keepdims=True)
    vel = np.gradient(j[:, 0], axis=0)
    vel[:, 1] = 0
    return np.sum(vel * fwd, -1)


def test_bandai_walk(mocap_root):
    path = mocap_root / "bandai/dataset-1/data/dataset-1_walk_active_001.bvh"
    m = load_mocap(path)
    assert (m.unit, m.up_axis) == ("cm", "Y")
    assert m.fps == pytest.approx(30.0, abs=1e-3)
    assert all(len(c) == 6 for c in m.meta["channels"][:1] + [c for c in m.meta["channels"] if c])
    # bone lengths in every frame equal the skeleton offsets (position channels carry the offsets),
    # except Hips, whose position channels are its world position
    P = m.positions
    for j in range(1, m.num_joints):
        if m.names[j] == "Hips":
            continue
        d = np.linalg.norm(P[:, j] - P[:, m.parents[j]], axis=-1)
        np.testing.assert_allclose(d, np.linalg.norm(m.offsets[j]), atol=1e-3)
    # feet on the floor, head at a standing height (SMPL head joint: skull base)
    mo = load_smpl22(path)
    j = mo.joints
    floor = np.percentile(j[:, [7, 8, 10, 11], 1].min(1), 5)
    assert -0.03 < floor < 0.08
    assert 1.25 < j[0, 15, 1] - floor < 1.8
    assert 0.8 < j[0, 0, 1] - floor < 1.1
    # walking forward: the root moves along the facing computed from LEFT minus RIGHT hip
    assert np.mean(_facing_speed(j) > 0) > 0.9
    # 30 -> 20 fps
    assert mo.fps == 20 and mo.num_frames == (m.num_frames - 1 - mo.dropped_frames) * 2 // 3 + 1
    # rest offsets of direct bones are the source bone lengths: thigh = |LowerLeg_L offset|
    assert np.linalg.norm(mo.offsets[4]) == pytest.approx(np.linalg.norm(m.offsets[m.index("LowerLeg_L")]), abs=1e-9)


def test_bandai_walk_back_moves_backward(mocap_root):
    mo = load_smpl22(mocap_root / "bandai/dataset-1/data/dataset-1_walk-back_normal_001.bvh")
    assert np.mean(_facing_speed(mo.joints) < 0) > 0.9


def test_cmu_bvh_tpose_dropped(mocap_root):
    path = mocap_root / "cmu/bvh/02/02_01.bvh"
    m = load_mocap(path)
    assert (m.unit, m.up_axis) == ("cm", "Y") and m.fps == pytest.approx(120.0, abs=1e-2)
    j, rig = map_positions(m.names, m.positions)
    assert rig.name == "daz"
    assert is_tpose(j[:1])[0] and not is_tpose(j[10:11])[0]
    mo = load_smpl22(path)
    assert 1 <= mo.dropped_frames <= 10
    assert not is_tpose(mo.joints[:1])[0]
    assert mo.num_frames == (m.num_frames - 1 - mo.dropped_frames) // 6 + 1
    floor = np.percentile(mo.joints[:, [7, 8, 10, 11], 1].min(1), 5)
    assert -0.03 < floor < 0.08
    head_top = m.positions[:, m.index("head")] - floor  # Daz head joint ~ skull base
    assert 1.3 < np.median(head_top[:, 1]) < 1.8
    assert np.mean(_facing_speed(mo.joints) > 0) > 0.8  # 02_01 is a walk
    assert load_smpl22(path, drop_tpose=False).dropped_frames == 0
