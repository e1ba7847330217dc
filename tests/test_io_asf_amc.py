"""ASF/AMC reader: hand-derived FK of the Acclaim conventions, units, and real CMU and HDM05 files
(~1.7 m people from the 0.45 convention, exact bone lengths, left/right, agreement with CMU's BVH
conversion of the same take)."""
import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.asf_amc import amc_fps, find_asf, load_amc, load_asf
from shapemove.core.io.mocap import load_mocap, load_smpl22
from shapemove.core.io.rig_map import map_positions

ASF = """# test skeleton
:version 1.10
:name test
:units
  mass 1.0
  length 1.0
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name a
     direction 1 0 0
     length 10
     axis 0 0 90 XYZ
     dof rx
     limits (-180 180)
  end
  begin
     id 2
     name b
     direction 0 1 0
     length 5
     axis 0 0 0 XYZ
     dof rx rz
  end
:hierarchy
  begin
    root a
    a b
  end
"""

AMC = """:FULLY-SPECIFIED
:DEGREES
1
root 1 2 3 0 0 0
a 0
b 0 0
2
root 0 0 0 0 90 0
a 90
b 0 90
3
root 0 0 0 0 0 0
a 0
b 90 90
"""


def _write(tmp_path, asf=ASF, amc=AMC, name="t"):
    (tmp_path / f"{name}.asf").write_text(asf)
    p = tmp_path / f"{name}_01.amc"
    p.write_text(amc)
    return p


def test_acclaim_fk_hand_derived(tmp_path):
    m = load_amc(_write(tmp_path), fps=60)
    assert m.names == ["root", "a", "b", "b_End"] and list(m.parents) == [-1, 0, 1, 2]
    assert m.fps == 60 and m.num_frames == 3 and m.up_axis == "Y"
    inch = 0.0254  # ':units length 1.0' = inches
    P = m.positions / inch
    # frame 1: rest pose at (1,2,3); bones start where their parent ends
    np.testing.assert_allclose(P[0], [[1, 2, 3], [1, 2, 3], [11, 2, 3], [11, 7, 3]], atol=1e-9)
    # frame 2: root Ry(90); a's rx in its axis frame C=Rz(90) is a rotation about Y: W_a = Ry(180);
    # b's rz(90) turns +Y into -X, W_a turns that into +X
    np.testing.assert_allclose(P[1, 2], [-10, 0, 0], atol=1e-9)
    np.testing.assert_allclose(P[1, 3], [-5, 0, 0], atol=1e-9)
    # frame 3: dof 'rx rz' compose as Rz @ Rx (fixed axes, listed order): +Y -> +Z
    np.testing.assert_allclose(P[2, 3] - P[2, 2], [0, 0, 5], atol=1e-9)
    np.testing.assert_allclose(m.bone_lengths()[1:] / inch, [0, 10, 5], atol=1e-9)


def test_units_length_and_radians(tmp_path):
    half_pi = "1.5707963267948966"
    asf = ASF.replace("length 1.0", "length 0.45").replace("angle deg", "angle rad").replace(
        "axis 0 0 90", f"axis 0 0 {half_pi}")
    amc = AMC.replace(":DEGREES", ":RADIANS").replace("a 90", f"a {half_pi}").replace(
        "b 0 90", f"b 0 {half_pi}").replace("root 0 0 0 0 90 0", f"root 0 0 0 0 {half_pi} 0")
    m = load_amc(_write(tmp_path, asf, amc), fps=60)
    scale = 0.0254 / 0.45
    np.testing.assert_allclose(m.positions[0, 3], np.array([11, 7, 3]) * scale, atol=1e-12)
    np.testing.assert_allclose(m.positions[1, 3], np.array([-5, 0, 0]) * scale, atol=1e-9)


def test_amc_errors(tmp_path):
    with pytest.raises(ShapeMoveError, match="lines for 'b'"):
        load_amc(_write(tmp_path, amc=AMC.replace("b 90 90\n", "")), fps=60)
    with pytest.raises(ShapeMoveError, match="does not define"):
        load_amc(_write(tmp_path, amc=AMC.replace("a 0\nb 90 90", "zz 0\nb 90 90")), fps=60)
    with pytest.raises(ShapeMoveError, match="expected 2 per frame"):
        load_amc(_write(tmp_path, amc=AMC.replace("b 0 90", "b 0 90 4")), fps=60)
    _write(tmp_path, name="u")  # now two ASFs (t.asf, u.asf), neither named after 'zz'
    orphan = tmp_path / "zz_01.amc"
    orphan.write_text(AMC)
    with pytest.raises(ShapeMoveError, match="cannot find its ASF"):
        load_amc(orphan)
    assert load_amc(orphan, asf=tmp_path / "t.asf", fps=60).num_frames == 3


def test_find_asf_and_fps(mocap_root):
    assert find_asf(mocap_root / "cmu/asfamc/02/02_01.amc").name == "02.asf"
    hdm = mocap_root / "hdm05/bd/HDM_bd_kickLFront1Reps_001_120.amc"
    assert find_asf(hdm).name == "HDM_bd.asf"
    assert amc_fps(hdm) == 120 and amc_fps(mocap_root / "cmu/asfamc/02/02_01.amc") == 120
    assert amc_fps("13_30.amc") == 120  # a CMU trial number is not a frame rate


def test_cmu_asf_units_and_bones(mocap_root):
    path = mocap_root / "cmu/asfamc/02/02_01.amc"
    m = load_mocap(path)
    n_frames = sum(1 for line in path.read_text().splitlines() if line.strip().isdigit())
    assert m.num_frames == n_frames and m.fps == 120 and m.subject == "02" and m.up_axis == "Y"
    # 0.45 convention: the rest skeleton (a standing T-pose) spans 1.54 m from the toe tips to the
    # head bone's end, a ~1.65 m person (taken as plain inches it would be 0.7 m, as cm 0.3 m)
    rest = _rest(m)
    height = rest[m.index("head_End"), 1] - min(rest[m.index("ltoes_End"), 1], rest[m.index("rtoes_End"), 1])
    assert 1.45 < height < 1.9
    # bone lengths in every frame = ASF length / 0.45 inches
    skel = load_asf(mocap_root / "cmu/asfamc/02/02.asf")
    P = m.positions
    for bone, child in (("lfemur", "ltibia"), ("rtibia", "rfoot"), ("lhumerus", "lradius"), ("upperneck", "head")):
        d = np.linalg.norm(P[:, m.index(child)] - P[:, m.index(bone)], axis=-1)
        np.testing.assert_allclose(d, skel.bones[bone].length / 0.45 * 0.0254, rtol=1e-9)


def _rest(m):
    from shapemove.core.geometry.fk import joints_from_offsets

    return joints_from_offsets(m.offsets, m.parents)


def test_cmu_asf_agrees_with_cmu_bvh(mocap_root):
    """CMU's own BVH conversion of the same take (another rig, frame 0 a T-pose): the limbs point
    the same way in every frame, so the ASF axis/dof conventions are right."""
    a = load_mocap(mocap_root / "cmu/asfamc/02/02_01.amc")
    b = load_mocap(mocap_root / "cmu/bvh/02/02_01.bvh")
    ja, _ = map_positions(a.names, a.positions)
    jb, _ = map_positions(b.names, b.positions[1:])
    n = min(len(ja), len(jb))
    for p, c in ((1, 4), (4, 7), (5, 8), (16, 18), (0, 12)):
        da, db = ja[:n, c] - ja[:n, p], jb[:n, c] - jb[:n, p]
        cos = np.sum(da * db, -1) / np.linalg.norm(da, axis=-1) / np.linalg.norm(db, axis=-1)
        assert np.median(cos) > 0.98 and np.percentile(cos, 5) > 0.95


def test_cmu_amc_smpl22(mocap_root):
    m = load_mocap(mocap_root / "cmu/asfamc/02/02_01.amc")
    mo = load_smpl22(mocap_root / "cmu/asfamc/02/02_01.amc")
    assert mo.rig == "cmu_asf" and mo.dropped_frames == 0
    assert mo.num_frames == (m.num_frames - 1) // 6 + 1
    j = mo.joints
    floor = np.percentile(j[:, [7, 8, 10, 11], 1].min(1), 5)
    assert -0.03 < floor < 0.08 and 1.35 < np.median(j[:, 15, 1]) - floor < 1.8
    # a walk: the root moves along cross(left_hip - right_hip, up)
    fwd = np.cross(j[:, 1] - j[:, 2], [0.0, 1.0, 0.0])
    vel = np.gradient(j[:, 0], axis=0)
    assert np.mean(np.sum(fwd * vel, -1) > 0) > 0.9


def test_hdm05_actors_and_left_right(mocap_root):
    kick = load_smpl22(mocap_root / "hdm05/bd/HDM_bd_kickLFront1Reps_001_120.amc")
    grab = load_smpl22(mocap_root / "hdm05/bd/HDM_bd_grabHighR_001_120.amc")
    assert kick.subject == "bd" and kick.fps == 20
    # kickLFront: the LEFT foot goes up; grabHighR: the RIGHT hand goes up
    j = kick.joints
    assert j[:, 7, 1].max() - j[:, 7, 1].min() > 2 * (j[:, 8, 1].max() - j[:, 8, 1].min())
    j = grab.joints
    assert j[:, 21, 1].max() > j[:, 20, 1].max() + 0.2
    # each actor has their own bone lengths
    bd = load_asf(mocap_root / "hdm05/bd/HDM_bd.asf").bones["lfemur"].length
    mm = load_asf(mocap_root / "hdm05/mm/HDM_mm.asf").bones["lfemur"].length
    assert bd != mm
    m = load_mocap(mocap_root / "hdm05/bd/HDM_bd_kickLFront1Reps_001_120.amc")
    np.testing.assert_allclose(np.linalg.norm(m.offsets[m.index("ltibia")]), bd / 0.45 * 0.0254, rtol=1e-12)
