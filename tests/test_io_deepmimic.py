"""DeepMimic motion reader: real clips from deepmimic.tar.xz (numbers checked against the humanoid3d
character) and hand-built valid / hostile files."""
import json
import math

import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.io import deepmimic as dm
from shapemove.core.io.mocap import load_mocap, load_smpl22

IDENTITY = [1.0, 0.0, 0.0, 0.0]


def frame(duration=1 / 30, root=(0.0, 0.9, 0.0), root_rot=IDENTITY, rknee=0.0, lknee=0.0, relbow=0.0, lelbow=0.0):
    row = [duration, *root, *root_rot, *IDENTITY, *IDENTITY]          # chest, neck
    row += [*IDENTITY, rknee, *IDENTITY, *IDENTITY, relbow]             # right hip, knee, ankle, shoulder, elbow
    row += [*IDENTITY, lknee, *IDENTITY, *IDENTITY, lelbow]             # left ...
    assert len(row) == 44
    return row


def write(tmp_path, data, name="m.txt"):
    p = tmp_path / name
    p.write_text(data if isinstance(data, str) else json.dumps(data))
    return p


def test_rest_pose_of_hand_built_clip(tmp_path):
    p = write(tmp_path, {"Loop": "none", "Frames": [frame(), frame(), frame(duration=0.0)]})
    m = load_mocap(p)
    assert m.fps == pytest.approx(30.0) and m.num_frames == 3 and m.up_axis == "Y" and m.unit == "m"
    P = m.positions[0]
    ix = {n: i for i, n in enumerate(m.names)}
    # humanoid3d attachments: root -> hip 0.0849 sideways, thigh 0.4215, shin 0.4099, chest 0.2362, neck 0.2239
    np.testing.assert_allclose(P[ix["right_ankle"]] - P[ix["right_hip"]], [0, -0.831416, 0], atol=1e-6)
    np.testing.assert_allclose(P[ix["neck"], 1] - P[ix["root"], 1], 0.460045, atol=1e-6)
    # ShapeMove frame: left at +X, facing +Z (toes in front of the ankles)
    assert P[ix["left_hip"], 0] == pytest.approx(0.084887) and P[ix["right_hip"], 0] == pytest.approx(-0.084887)
    assert P[ix["left_toe"], 2] - P[ix["left_ankle"], 2] == pytest.approx(dm.TOE_POINT[0])
    # FK of the offsets with the rotations reproduces the positions
    assert m.rotations.shape == (3, len(m.names), 3, 3)


def test_knee_and_elbow_bend_the_right_way(tmp_path):
    p = write(tmp_path, {"Frames": [frame(rknee=-math.pi / 2, lelbow=math.pi / 2)] * 2})
    m = load_mocap(p)
    P, ix = m.positions[0], {n: i for i, n in enumerate(m.names)}
    shin = P[ix["right_ankle"]] - P[ix["right_knee"]]
    np.testing.assert_allclose(shin, [0, 0, -0.40987], atol=1e-6)    # knee bends the shin BACKWARD (-Z)
    fore = P[ix["left_wrist"]] - P[ix["left_elbow"]]
    np.testing.assert_allclose(fore, [0, 0, 0.258947], atol=1e-6)    # elbow bends the forearm FORWARD (+Z)


def test_uneven_frame_times_are_resampled(tmp_path):
    frames = [frame(root=(0.1 * i, 0.9, 0.0)) for i in range(5)]
    frames[2][0] = 2 / 30                                               # one frame held twice as long
    m = load_mocap(write(tmp_path, {"Frames": frames}))
    assert m.fps == pytest.approx(30.0) and m.num_frames == 6          # 5 intervals of 1/30 s... plus 1
    # the root moves +X (DeepMimic forward) -> +Z in ShapeMove; linear in time across the long frame
    np.testing.assert_allclose(m.positions[:, 0, 2], [0, 0.1, 0.2, 0.25, 0.3, 0.4], atol=1e-9)


def test_wrap_loops_repeat_by_whole_cycles(tmp_path):
    turn = [math.cos(math.pi / 8), 0.0, math.sin(math.pi / 8), 0.0]  # 45 degrees about +Y at the end
    frames = [frame(root=(0.0, 0.9, 0.0)), frame(root=(0.5, 0.9, 0.0)), frame(root=(1.0, 0.9, 0.0), root_rot=turn)]
    m = load_mocap(write(tmp_path, {"Loop": "wrap", "Frames": frames}))  # 2/30 s per cycle -> 23 cycles...
    assert m.meta["cycles"] == dm.MAX_CYCLES                            # ...capped
    m = dm.load_deepmimic(write(tmp_path, {"Loop": "wrap", "Frames": frames}), loop_min_seconds=0.1)
    assert m.meta["cycles"] == 2 and m.num_frames == 5
    # the second cycle starts where the first ended and heads 45 degrees further round
    root = m.positions[:, 0]
    np.testing.assert_allclose(np.linalg.norm(np.diff(root[:, [0, 2]], axis=0), axis=1), 0.5, atol=1e-9)
    step2 = root[4] - root[3]
    assert math.degrees(math.atan2(step2[0], step2[2])) == pytest.approx(45.0, abs=1e-6)  # +Z turned towards +X


@pytest.mark.parametrize("content, message", [
    ("HIERARCHY\nROOT Hips\n", "invalid JSON"),
    ("[1, 2, 3]", "no \"Frames\""),
    ('{"Loop": "wrap"}', "no \"Frames\""),
    ('{"Frames": []}', "at least 2 frames"),
    ('{"Frames": "abc"}', "at least 2 frames"),
    ('{"Loop": 7, "Frames": [[0]]}', "unknown \"Loop\""),
    ('{"Frames": [[0.03, 1, 2], [0.03, 1, 2]]}', "has 3 values"),
    ("[" * 100000 + "]" * 100000, "invalid JSON"),
    ('{"Frames": [' + "[" + ", ".join(["NaN"] * 44) + "]" + "]}", "invalid JSON"),
])
def test_malformed_files_are_refused(tmp_path, content, message):
    with pytest.raises(ShapeMoveError, match=message):
        load_mocap(write(tmp_path, content))


def test_bad_numbers_are_refused(tmp_path):
    good = frame()
    cases = {
        "string": (good[:5] + ["x"] + good[6:], "not a number"),
        "bool": (good[:5] + [True] + good[6:], "not a number"),
        "huge": (good[:1] + [1e300] + good[2:], "out of range"),
        "zero quaternion": (good[:8] + [0, 0, 0, 0] + good[12:], "quaternion of length 0"),
        "negative duration": ([-0.1] + good[1:], "durations"),
    }
    for name, (row, message) in cases.items():
        with pytest.raises(ShapeMoveError, match=message):
            load_mocap(write(tmp_path, {"Frames": [row, row]}, name=f"{name.replace(' ', '_')}.txt"))
    with pytest.raises(ShapeMoveError, match="implausible frame duration"):
        load_mocap(write(tmp_path, {"Frames": [frame(duration=0.0)] * 3}, name="zero.txt"))
    (tmp_path / "bin.txt").write_bytes(b"\xff\xfe\x00junk")
    with pytest.raises(ShapeMoveError, match="binary data"):
        load_mocap(tmp_path / "bin.txt")


def test_size_and_frame_limits(tmp_path, monkeypatch):
    p = write(tmp_path, {"Frames": [frame()] * 50})
    monkeypatch.setattr(dm, "MAX_FRAMES", 10)
    with pytest.raises(ShapeMoveError, match="more than the limit"):
        load_mocap(p)
    monkeypatch.setattr(dm, "MAX_BYTES", 1000)
    with pytest.raises(ShapeMoveError, match="are refused"):
        load_mocap(p)


# ---- real clips ----------------------------------------------------------------------------------

def clip(mocap_root, name):
    return mocap_root / "deepmimic" / f"{name}.txt"


def test_walk_clip_numbers(mocap_root):
    path = clip(mocap_root, "humanoid3d_walk")
    m = load_mocap(path)
    # file: 39 frames of 0.033332 s, a wrap loop of 1.2666 s -> repeated to 2 cycles (>= 1.5 s)
    assert m.fps == pytest.approx(30.0, abs=0.01) and m.meta["frames_in_file"] == 39 and m.meta["cycles"] == 2
    ix = {n: i for i, n in enumerate(m.names)}
    P = m.positions
    # Y is up: the root (between the hips) stays 0.85-0.88 m above the floor
    assert 0.84 < P[:, ix["root"], 1].min() and P[:, ix["root"], 1].max() < 0.88
    # the feet touch the floor: soles (ankle - 5 cm foot box) reach y = 0 within 1 cm, never sink below -1 cm
    soles = P[:, [ix["left_ankle"], ix["right_ankle"]], 1] - 0.05
    assert abs(soles.min()) < 0.01
    assert soles.min(axis=1).max() < 0.05          # one foot on the ground at every frame of a walk
    # the walk goes forward (+Z), 1.24 m per cycle
    travel = P[-1, ix["root"]] - P[0, ix["root"]]
    assert travel[2] == pytest.approx(2 * 1.239, abs=0.02) and abs(travel[0]) < 0.2
    # tiling is seamless: no jump of the root at the cycle boundary
    step = np.linalg.norm(np.diff(P[:, ix["root"], [0, 2]], axis=0), axis=1)
    assert step.max() < 1.6 * np.median(step)

    s = load_smpl22(path)
    assert s.rig == "deepmimic" and s.num_frames == 51 and s.fps == 20.0   # 2.533 s at 20 fps
    bones = s.bone_lengths()
    assert bones[4] == pytest.approx(0.4215, abs=0.002) and bones[7] == pytest.approx(0.4099, abs=0.002)  # L thigh, shin
    assert bones[18] == pytest.approx(0.2748, abs=0.002)                    # left upper arm
    pelvis = s.joints[:, 0, 1]
    head = s.joints[:, 15, 1]
    assert 0.85 < np.median(pelvis) < 0.90 and 1.38 < np.median(head) < 1.44
    assert s.joints[:, 1, 0].mean() > s.joints[:, 2, 0].mean()             # left hip at +X


def test_every_shipped_clip_reads(mocap_root):
    files = sorted((mocap_root / "deepmimic").glob("humanoid3d_*.txt"))
    files += sorted((mocap_root / "deepmimic" / "long").glob("*.txt"))
    assert len(files) == 29
    frames = {}
    for f in files:
        s = load_smpl22(f)
        assert np.isfinite(s.joints).all() and s.num_frames >= 24, f.name
        frames[f.stem] = s.num_frames
    # roll: one frame of the file lasts two frame times; it is resampled, not skipped
    assert frames["humanoid3d_roll"] == 40 and frames["humanoid3d_long_walk1"] == 656
    # crawl: the pelvis stays low; the cartwheel turns upside down (feet above the head at some frame)
    crawl = load_smpl22(clip(mocap_root, "humanoid3d_crawl")).joints
    assert np.median(crawl[:, 0, 1]) < 0.45
    cart = load_smpl22(clip(mocap_root, "humanoid3d_cartwheel")).joints
    assert (cart[:, [7, 8], 1].max(axis=1) > cart[:, 15, 1]).any()


def test_fuzzed_files_load_or_raise_shapemove_error(tmp_path):
    """Truncations and byte flips of a valid file: a Mocap or a ShapeMoveError, nothing else."""
    base = json.dumps({"Loop": "wrap", "Frames": [frame(root=(0.1 * i, 0.9, 0.0)) for i in range(6)]}).encode()
    rng = np.random.default_rng(0)
    p = tmp_path / "fuzz.txt"
    outcomes = {"ok": 0, "refused": 0}
    for k in range(300):
        data = bytearray(base)
        if k % 3 == 0:
            data = data[: rng.integers(1, len(data))]
        else:
            for _ in range(rng.integers(1, 6)):
                data[rng.integers(len(data))] = int(rng.choice(list(b"0123456789-.e,[]{}\" x")))
        p.write_bytes(bytes(data))
        try:
            m = load_mocap(p)
            assert np.isfinite(m.positions).all()
            outcomes["ok"] += 1
        except ShapeMoveError:
            outcomes["refused"] += 1
    assert outcomes["ok"] >= 5 and outcomes["refused"] >= 150  # both paths exercised (measured: 7 / 293)
