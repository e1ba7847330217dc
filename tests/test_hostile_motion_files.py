"""Memory and time bombs in motion files (issue 11): each hostile file is built on the spot and
loaded in a child process limited to 1 GB more address space and 30 s; it must end in a
ShapeMoveError sentence, well inside both limits."""
import numpy as np
import pytest

from limited_run import run_limited
from mocap_synth import MIXAMO, MIXAMO_PARENT, SMPL_REST, bvh_text

GB = 1 << 30


def _mixamo_bvh(frames: int, frame_time: float) -> str:
    names = list(MIXAMO)
    parents = [-1] + [names.index(MIXAMO_PARENT[n]) for n in names[1:]]
    rest = SMPL_REST[[MIXAMO[n] for n in names]]
    t = np.arange(frames)[:, None]
    motion = 20 * np.sin(0.05 * t + np.arange(6 + 3 * (len(names) - 1)))  # swinging joints, not a T-pose
    motion[:, :3] = rest[0] * 100 + np.array([0.0, 0.0, 1.0]) * t
    for arm, sign in (("LeftArm", -1), ("RightArm", 1)):  # arms down: no T-pose lead-in to cut
        motion[:, 6 + 3 * (names.index(arm) - 1)] += sign * 70
    return bvh_text(names, parents, rest * 100, motion, frame_time=frame_time)


def _chain_bvh(joints: int, frames: int, data_frames: int) -> str:
    """``joints`` nested joints with no channels under a root with one: tiny file, huge (T,J)."""
    head = ["HIERARCHY", "ROOT r", "{", "OFFSET 0 0 0", "CHANNELS 1 Xposition"]
    head += [f"JOINT j{i}\n{{\nOFFSET 0 1 0" for i in range(joints - 1)] + ["}"] * joints
    return "\n".join(head + ["MOTION", f"Frames: {frames}", "Frame Time: 0.01"] + ["0"] * data_frames) + "\n"


def _asf(bones: int, dof: bool = True) -> str:
    out = [":version 1.10", ":name x", ":units", "  mass 1.0", "  length 0.45", "  angle deg", ":root",
           "  order TX TY TZ RX RY RZ", "  axis XYZ", "  position 0 0 0", "  orientation 0 0 0", ":bonedata"]
    for i in range(bones):
        out += ["begin", f"  id {i + 1}", f"  name b{i}", "  direction 0 1 0", "  length 1", "  axis 0 0 0 XYZ"]
        out += ["  dof rx"] if dof else []
        out += ["end"]
    out += [":hierarchy", "begin", "  root b0"] + [f"  b{i} b{i + 1}" for i in range(bones - 1)] + ["end"]
    return "\n".join(out) + "\n"


def _check(results, match):
    for r in results:
        assert r["outcome"] == "ShapeMoveError", r
        assert any(m in r["message"] for m in match), r
        assert r["max_rss"] < GB, r
        assert r["seconds"] < 30, r


def test_bvh_and_amc_bombs(tmp_path):
    cases, match = [], []

    def add(name, text, asf=None, expect=""):
        p = tmp_path / name
        p.write_text(text)
        cases.append({"path": str(p), "asf": asf})
        match.append(expect)

    # 1. ~300 KB: 1,999 joints x 20,000 frames declared (was > 4 GB)
    add("joints.bvh", _chain_bvh(1999, 20000, 20000), expect="joint-frames")
    # 2. 'Frame Time: 2.0' on 9,000 frames: 5 h of motion upsampled 40x to 20 fps (was 2.9 GB, > 300 s)
    add("slow.bvh", _mixamo_bvh(9000, 2.0), expect="longer than 3600 s")
    # 3. header claims far more frames than the data holds (nothing allocated for them)
    add("claims.bvh", _chain_bvh(3, 10**9, 5), expect="joint-frames")
    add("claims2.bvh", _chain_bvh(3, 600000, 5), expect="truncated")
    # 4. AMC: 2.5 M frame numbers on a 100-bone skeleton without values (frames x joints bomb)
    asf = tmp_path / "s.asf"
    asf.write_text(_asf(100, dof=False))
    add("frames.amc", "\n".join(str(i) for i in range(1, 2_500_000)) + "\n", asf=str(asf), expect="joint-frames")
    # 5. ASF with 5,000 bones (hierarchy check was quadratic) and one over the bone limit
    big = tmp_path / "big.asf"
    big.write_text(_asf(5000))
    add("big.amc", "1\nroot 0 0 0 0 0 0\n", asf=str(big), expect="more than 1000 bones")
    # 6. a 300 MB (sparse) BVH is refused before it is read (BVH rows are streamed: up to 256 MB)
    huge = tmp_path / "huge.bvh"
    with open(huge, "wb") as fh:
        fh.truncate(300 * 2**20)
    cases.append({"path": str(huge), "asf": None})
    match.append("larger than 256 MB")
    # 7. a 50 MB hierarchy of junk tokens
    add("junk.bvh", "HIERARCHY\nROOT a\n{\n" + "x " * 5_000_000 + "\nMOTION\n", expect="BVH hierarchy is")
    # 8. DeepMimic: a 100 MB file is refused unread; deep nesting is a sentence
    dm = tmp_path / "huge.txt"
    with open(dm, "wb") as fh:
        fh.truncate(100 * 2**20)
    cases.append({"path": str(dm), "asf": None})
    match.append("are refused")
    add("nested.txt", '{"Loop": "none", "Frames": ' + "[" * 200000 + "]" * 200000 + "}", expect="not a DeepMimic motion")
    results = run_limited(cases, timeout_s=30, mem_bytes=GB)
    assert len(results) == len(cases)
    for r, m in zip(results, match):
        _check([r], [m])


def test_deepmimic_at_its_size_limit_stays_under_1_gb(tmp_path):
    """The largest DeepMimic file the reader accepts (just under its byte limit) loads in < 1 GB."""
    from shapemove.core.io import deepmimic

    row = [1 / 30, 0.0, 0.85, 0.0] + [1.0, 0.0, 0.0, 0.0] * 4 + [-0.3] + [1.0, 0.0, 0.0, 0.0] * 2 + [0.3] + \
          [1.0, 0.0, 0.0, 0.0] + [-0.3] + [1.0, 0.0, 0.0, 0.0] * 2 + [0.3]
    assert len(row) == 44
    line = "    [" + ", ".join(f"{v:.6f}" for v in row) + "],\n"
    n = min(int(0.95 * deepmimic.MAX_BYTES) // len(line), deepmimic.MAX_FRAMES - 1)
    p = tmp_path / "big.txt"
    p.write_text('{\n"Loop": "none",\n"Frames":\n[\n' + line * n + line.rstrip(",\n") + "\n]\n}\n")
    (r,) = run_limited([{"path": str(p), "asf": None}], timeout_s=30, mem_bytes=GB)
    assert r["outcome"] in ("ok", "ShapeMoveError"), r
    assert r["max_rss"] < GB and r["seconds"] < 30, r


def test_asf_with_many_bones_is_fast(tmp_path):
    """999 chained bones (under the limit) parse in well under a second: no quadratic step."""
    import time

    from shapemove.core.io.asf_amc import parse_asf

    t0 = time.perf_counter()
    skel = parse_asf(_asf(999))
    assert len(skel.bones) == 999
    assert time.perf_counter() - t0 < 1.0


def test_resampling_is_capped():
    from shapemove.core.errors import ShapeMoveError
    from shapemove.core.io.resample import resample_positions, sample_times

    x = np.zeros((1000, 22, 3))
    assert resample_positions(x, 120.0).shape == (167, 22, 3)
    with pytest.raises(ShapeMoveError, match="longer than 3600 s"):
        resample_positions(x, 0.25)  # 4,000 s
    with pytest.raises(ShapeMoveError, match="joint-frames"):
        sample_times(3000, 1.0, 1000.0, joints=22)  # 3 M output frames
    with pytest.raises(ShapeMoveError, match="positive"):
        sample_times(10, float("nan"), 20.0)


def test_real_sized_clip_still_loads(tmp_path):
    """A 2-minute 120 fps clip (14,400 frames, 22 joints) loads inside the limits."""
    p = tmp_path / "long.bvh"
    p.write_text(_mixamo_bvh(14400, 1 / 120))
    (r,) = run_limited([{"path": str(p), "asf": None}], timeout_s=30, mem_bytes=GB)
    assert r["outcome"] == "ok", r
    assert r["max_rss"] < GB


def test_amass_npz_bombs_and_pickles(tmp_path):
    """AMASS .npz: a header declaring 80 GB of poses and a pickled array are refused unread."""
    import io
    import zipfile

    from shapemove.core.errors import ShapeMoveError
    from shapemove.core.io.amass import read_amass_npz

    p = tmp_path / "bomb.npz"
    np.savez(p, trans=np.zeros((10, 3)), mocap_framerate=np.array(120.0))
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": (10**8, 100)})
    with zipfile.ZipFile(p, "a") as zf:
        zf.writestr("poses.npy", buf.getvalue())
    with pytest.raises(ShapeMoveError, match="MB, more than any AMASS motion file"):
        read_amass_npz(p)
    marker = tmp_path / "marker"

    class Evil:
        def __reduce__(self):
            return exec, (f"open({str(marker)!r}, 'w').close()",)

    np.savez(p, poses=np.array([Evil()], dtype=object), trans=np.zeros((1, 3)), mocap_framerate=np.array(120.0))
    with pytest.raises(ShapeMoveError, match="poses is a pickled Python object"):
        read_amass_npz(p)
    assert not marker.exists()
    p.write_bytes(b"PK\x03\x04 truncated")
    with pytest.raises(ShapeMoveError, match="not a readable AMASS motion file"):
        read_amass_npz(p)
