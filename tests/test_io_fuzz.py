"""Fuzz: hundreds of mutated, truncated and garbage BVH / ASF / AMC files must either load into
finite joints or raise ShapeMoveError -- never another exception, never a hang."""
import time

import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.asf_amc import load_amc
from shapemove.core.io.mocap import load_mocap, mocap_to_smpl22

BAD_TOKENS = ["nan", "NaN", "inf", "-inf", "1e308", "-1e309", "1e400", "abc", "{", "}", "", "999999999999",
              "-0", "CHANNELS", "JOINT", "End", "MOTION", "Frames:", "0x1F", "1,5", "\u00e9", "1e-320", "root"]
CASES = 130  # per base file; 3 base files -> 390 files


def _small_bvh(path, frames=8):
    lines = path.read_text().splitlines()
    k = next(i for i, s in enumerate(lines) if s.startswith("Frame Time"))
    head = [("Frames: %d" % frames if s.startswith("Frames") else s) for s in lines[: k + 1]]
    return "\n".join(head + lines[k + 1: k + 1 + frames]) + "\n"


def _small_amc(path, frames=5):
    out, n = [], 0
    for s in path.read_text(errors="replace").splitlines():
        if s.strip().isdigit():
            n += 1
            if n > frames:
                break
        out.append(s)
    return "\n".join(out) + "\n"


def mutate(text: str, rng: np.random.Generator) -> bytes:
    """One random corruption of a text file."""
    kind = int(rng.integers(0, 11))
    lines = text.split("\n")
    if kind == 0:  # truncate anywhere
        return text.encode()[: int(rng.integers(0, len(text)))]
    if kind == 1:  # drop lines
        for _ in range(int(rng.integers(1, 4))):
            lines.pop(int(rng.integers(0, len(lines))))
    elif kind == 2:  # duplicate or swap lines
        i, j = rng.integers(0, len(lines), 2)
        if rng.random() < 0.5:
            lines.insert(int(i), lines[int(j)])
        else:
            lines[i], lines[j] = lines[j], lines[i]
    elif kind in (3, 4, 5):  # replace tokens (numbers, keywords) with bad ones
        for _ in range(int(rng.integers(1, 4))):
            i = int(rng.integers(0, len(lines)))
            toks = lines[i].split()
            if toks:
                toks[int(rng.integers(0, len(toks)))] = BAD_TOKENS[int(rng.integers(0, len(BAD_TOKENS)))]
                lines[i] = " ".join(toks)
    elif kind == 6:  # wrong channel / dof counts
        i = int(rng.integers(0, len(lines)))
        lines[i] = lines[i].replace("CHANNELS 6", f"CHANNELS {int(rng.integers(0, 9))}").replace(
            "CHANNELS 3", f"CHANNELS {int(rng.integers(0, 9))}").replace("dof rx ry rz", "dof rx ry")
        for k, s in enumerate(lines):
            if "CHANNELS" in s and rng.random() < 0.2:
                lines[k] = s.replace("CHANNELS 6", "CHANNELS 7")
    elif kind == 7:  # random bytes flipped
        b = bytearray(text.encode())
        for _ in range(int(rng.integers(1, 20))):
            b[int(rng.integers(0, len(b)))] = int(rng.integers(0, 256))
        return bytes(b)
    elif kind == 8:  # binary garbage inserted
        b = text.encode()
        i = int(rng.integers(0, len(b)))
        return b[:i] + rng.integers(0, 256, int(rng.integers(1, 200)), dtype=np.uint8).tobytes() + b[i:]
    elif kind == 9:  # absurd header values
        repl = {"Frames:": ["Frames: 999999999", "Frames: 0", "Frames: -3", "Frames: 2.5"],
                "Frame Time:": ["Frame Time: 0", "Frame Time: -1", "Frame Time: nan", "Frame Time: 1e-9"],
                "length": ["length 0", "length -1", "length 1e300"], ":DEGREES": [":RADIANS"]}
        for k, s in enumerate(lines):
            for key, opts in repl.items():
                if s.strip().startswith(key) and rng.random() < 0.5:
                    lines[k] = opts[int(rng.integers(0, len(opts)))]
    else:  # huge numbers everywhere on one line
        i = int(rng.integers(0, len(lines)))
        lines[i] = " ".join("1e30" if t.replace(".", "").replace("-", "").isdigit() else t for t in lines[i].split())
    return "\n".join(lines).encode("utf-8", errors="replace")


def _check(load, path):
    t0 = time.perf_counter()
    try:
        m = load(path)
        assert np.all(np.isfinite(m.positions))
        try:
            mo = mocap_to_smpl22(m)
            assert np.all(np.isfinite(mo.joints))
        except ShapeMoveError:
            pass
        ok = True
    except ShapeMoveError as exc:
        assert str(exc)
        ok = False
    assert time.perf_counter() - t0 < 3.0, f"{path.name} took too long"
    return ok


@pytest.fixture(scope="module")
def bases(mocap_root):
    bvh = _small_bvh(mocap_root / "bandai/dataset-1/data/dataset-1_walk_active_001.bvh")
    daz = _small_bvh(mocap_root / "cmu/bvh/02/02_01.bvh")
    asf = (mocap_root / "cmu/asfamc/02/02.asf").read_text()
    amc = _small_amc(mocap_root / "cmu/asfamc/02/02_01.amc")
    return bvh, daz, asf, amc


def test_fuzz_bvh(bases, tmp_path):
    rng = np.random.default_rng(1234)
    loaded = 0
    for base in bases[:2]:
        p = tmp_path / "f.bvh"
        p.write_text(base)
        assert _check(load_mocap, p)  # the unmutated base loads
        for _ in range(CASES):
            p.write_bytes(mutate(base, rng))
            loaded += _check(load_mocap, p)
    assert 0 < loaded < 2 * CASES  # some mutations stay valid, most do not


def test_fuzz_asf_amc(bases, tmp_path):
    _, _, asf, amc = bases
    rng = np.random.default_rng(99)
    asf_path, amc_path = tmp_path / "02.asf", tmp_path / "02_01.amc"
    load = lambda p: load_amc(p, asf=asf_path)  # noqa: E731
    asf_path.write_text(asf)
    amc_path.write_text(amc)
    assert _check(load, amc_path)
    for i in range(CASES):
        if i % 2:
            asf_path.write_bytes(mutate(asf, rng))
            amc_path.write_text(amc)
        else:
            asf_path.write_text(asf)
            amc_path.write_bytes(mutate(amc, rng))
        _check(load, amc_path)


@pytest.mark.parametrize("content", [b"", b"\0" * 100, bytes(range(256)) * 8, b"HIERARCHY", b"HIERARCHY\nROOT",
                                     b"MOTION\nFrames: 1\nFrame Time: 0.1\n1 2 3", b"{" * 5000 + b"}" * 5000,
                                     b"HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
                                     + b"JOINT b\n{\nOFFSET 0 1 0\n" * 3000])
def test_garbage_files(tmp_path, content):
    for ext in (".bvh", ".amc", ".npz"):
        p = tmp_path / f"g{ext}"
        p.write_bytes(content)
        (tmp_path / "g.asf").write_bytes(content)
        with pytest.raises(ShapeMoveError):
            load_mocap(p)
