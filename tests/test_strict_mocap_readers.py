"""Strict mocap readers (issue 28): a real Bandai BVH and a real CMU ASF/AMC, each damaged in one
place the old readers read silently wrong (a value added or lost in a row, a CHANNELS line
missing, a Frames count off, a frame time of 2 s, radians declared over degrees), must be refused
with a ShapeMoveError naming the file, the line and what was expected; the CLI says it in one line
(exit 2) and writes nothing. The overrides (--source-fps, --angle-unit) read them as intended."""
from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.asf_amc import load_amc
from shapemove.core.io.bvh import load_bvh
from shapemove.core.io.mocap import load_smpl22

WALK = "bandai/dataset-2/data/dataset-2_walk_masculine_003.bvh"


@pytest.fixture(scope="module")
def walk(mocap_root):
    return (mocap_root / WALK).read_text()


def _rows_at(lines: list[str]) -> int:
    """Index of the first data row (the line after 'Frame Time')."""
    return next(i for i, s in enumerate(lines) if s.startswith("Frame Time")) + 1


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_intact_walk_loads(walk, tmp_path):
    m = load_bvh(_write(tmp_path, "walk.bvh", walk))
    assert m.num_frames == 220 and abs(m.fps - 30.0) < 1e-3


@pytest.mark.parametrize("change", [+1, -1])
def test_row_with_a_value_added_or_lost(walk, tmp_path, change):
    lines = walk.splitlines()
    k = _rows_at(lines) + 50  # row 51
    toks = lines[k].split()
    channels = len(toks)
    lines[k] = " ".join(toks + ["0.5"] if change > 0 else toks[:-1])
    p = _write(tmp_path, "bad.bvh", "\n".join(lines) + "\n")
    with pytest.raises(ShapeMoveError) as e:
        load_bvh(p)
    msg = str(e.value)
    assert str(p) in msg and f"line {k + 1}:" in msg and "row 51" in msg
    assert f"has {channels + change} values" in msg and f"declares {channels} channels" in msg


def test_joint_without_channels(walk, tmp_path):
    lines = walk.splitlines()
    k = next(i for i, s in enumerate(lines) if "JOINT LowerLeg_L" in s)
    cut = next(i for i in range(k, k + 5) if "CHANNELS" in lines[i])
    del lines[cut]
    p = _write(tmp_path, "nochan.bvh", "\n".join(lines) + "\n")
    with pytest.raises(ShapeMoveError) as e:
        load_bvh(p)
    assert f"line {k + 1}:" in str(e.value) and "'LowerLeg_L' has no CHANNELS line" in str(e.value)


@pytest.mark.parametrize("frames, words", [(219, "more data rows than its 'Frames: 219'"),
                                           (221, "truncated: 'Frames: 221'")])
def test_frame_count_that_disagrees_with_the_rows(walk, tmp_path, frames, words):
    text = re.sub(r"Frames:\s*220", f"Frames: {frames}", walk)
    p = _write(tmp_path, "count.bvh", text)
    with pytest.raises(ShapeMoveError, match=re.escape(words)) as e:
        load_bvh(p)
    line = _rows_at(walk.splitlines()) - 1  # the Frames line (1-based), just before Frame Time
    assert f"(line {line})" in str(e.value) and str(p) in str(e.value)


@pytest.mark.parametrize("dt", ["2.0", "0.00001"])
def test_implausible_frame_time_and_its_override(walk, tmp_path, dt):
    p = _write(tmp_path, "slow.bvh", re.sub(r"Frame Time:\s*\S+", f"Frame Time: {dt}", walk))
    with pytest.raises(ShapeMoveError, match="implausible for motion capture.*--source-fps"):
        load_bvh(p)
    intact = load_smpl22(_write(tmp_path, "walk.bvh", walk))
    header = float(re.search(r"Frame Time:\s*(\S+)", walk).group(1))
    forced = load_smpl22(p, source_fps=1.0 / header)  # the user says what the header should have said
    np.testing.assert_allclose(forced.joints, intact.joints, atol=1e-9)


def test_cli_refuses_a_damaged_row_in_one_line(walk, tmp_path):
    lines = walk.splitlines()
    k = _rows_at(lines) + 3
    lines[k] += " 1.0"
    p = _write(tmp_path, "bad.bvh", "\n".join(lines) + "\n")
    out = tmp_path / "out.npz"
    r = subprocess.run([sys.executable, "-m", "shapemove", "retarget", "--motion", str(p), "--betas", "1",
                        "--naive", "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert f"line {k + 1}:" in r.stderr and "declares" in r.stderr
    assert not out.exists() and not list(tmp_path.glob("out*"))


# -- ASF/AMC -------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def cmu(mocap_root):
    folder = mocap_root / "cmu/asfamc/02"
    amc = (folder / "02_01.amc").read_text().splitlines()
    first = next(i for i, s in enumerate(amc) if s.strip().isdigit())
    nxt = [i for i, s in enumerate(amc) if s.strip().isdigit()][120]  # 120 frames: 1 s
    return (folder / "02.asf").read_text(), "\n".join(amc[:nxt]) + "\n", first


def _amc_pair(tmp_path, asf, amc):
    a = _write(tmp_path, "s.asf", asf)
    return _write(tmp_path, "s_01.amc", amc), a


def test_amc_line_with_a_value_added(cmu, tmp_path):
    asf, amc, first = cmu
    lines = amc.splitlines()
    k = next(i for i in range(first, len(lines)) if lines[i].startswith("lfemur"))
    lines[k] += " 3.0"
    p, a = _amc_pair(tmp_path, asf, "\n".join(lines) + "\n")
    with pytest.raises(ShapeMoveError) as e:
        load_amc(p, asf=a)
    assert f"line {k + 1}:" in str(e.value) and "4 values for 'lfemur', expected 3" in str(e.value)
    assert str(p) in str(e.value)


def _to_radians(asf: str, amc: str) -> tuple[str, str]:
    """The same clip with every angle written in radians and 'angle rad' declared."""
    def conv(line: str, keep: int, upto: int | None = None) -> str:
        toks = line.split()
        end = len(toks) if upto is None else upto
        return " ".join(toks[:keep] + [repr(float(np.radians(float(t)))) for t in toks[keep:end]] + toks[end:])

    out_asf = []
    for s in asf.replace("angle deg", "angle rad").splitlines():
        t = s.split()
        out_asf.append(conv(s, 1, 4) if t and t[0] in ("axis", "orientation") and len(t) >= 4 else s)
    out_amc = []
    for s in amc.replace(":DEGREES", ":RADIANS").splitlines():
        t = s.split()
        if not t or s.startswith((":", "#")) or t[0].isdigit():
            out_amc.append(s)
        else:
            out_amc.append(conv(s, 4) if t[0] == "root" else conv(s, 1))  # root: TX TY TZ stay lengths
    return "\n".join(out_asf) + "\n", "\n".join(out_amc) + "\n"


def test_radians_declared_over_degrees(cmu, tmp_path):
    asf, amc, _ = cmu
    intact = load_amc(*_amc_pair(tmp_path, asf, amc)[:1], asf=tmp_path / "s.asf")
    bad = tmp_path / "bad"
    bad.mkdir()
    p, a = _amc_pair(bad, asf.replace("angle deg", "angle rad"), amc)
    with pytest.raises(ShapeMoveError, match=r"declares angles in radians.*--angle-unit deg") as e:
        load_amc(p, asf=a)
    assert str(a) in str(e.value) and "the ASF declares angles in radians" in str(e.value)
    forced = load_amc(p, asf=a, angle_unit="deg")  # the override covers the ASF's axes too
    np.testing.assert_allclose(forced.positions, intact.positions, atol=1e-9)
    # the AMC declaring radians over its degrees: refused too, naming the line that declares it
    amc_rad = tmp_path / "amc_rad"
    amc_rad.mkdir()
    p, a = _amc_pair(amc_rad, asf, amc.replace(":DEGREES", ":RADIANS"))
    with pytest.raises(ShapeMoveError, match=r"the AMC \(:RADIANS, line \d+\) declares angles in radians.*--angle-unit"):
        load_amc(p, asf=a)
    # a clip really in radians is read, not refused, and gives the same joints
    rad = tmp_path / "rad"
    rad.mkdir()
    p, a = _amc_pair(rad, *_to_radians(asf, amc))
    np.testing.assert_allclose(load_amc(p, asf=a).positions, intact.positions, atol=1e-6)
