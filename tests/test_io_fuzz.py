"""Fuzz: >= 500 mutated, truncated and garbage BVH / ASF / AMC / DeepMimic files, each loaded
(``load_mocap`` + ``mocap_to_smpl22``) in its own forked process limited to 30 s and 1 GB more
address space (tests/limited_run.py). Every case must load into finite joints or raise
ShapeMoveError -- never another exception, a hang, a crash or more than 1 GB.

Bases are synthetic (always there) plus small real clips when the mocap archives are present."""
from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import REQUIRE_DATA
from limited_run import run_limited
from mocap_synth import MIXAMO, MIXAMO_PARENT, SMPL_REST, bvh_text

from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.mocap import load_mocap

GB = 1 << 30
CASES = 130  # per base kind: BVH, ASF, AMC, DeepMimic -> 520 mutated files (+ the unmutated bases)
BAD_TOKENS = ["nan", "NaN", "inf", "-inf", "1e308", "-1e309", "1e400", "abc", "{", "}", "", "999999999999",
              "-0", "CHANNELS", "JOINT", "End", "MOTION", "Frames:", "0x1F", "1,5", "\u00e9", "1e-320", "root",
              "[", "]", "null", "true", '"x"', "[[[[[[[[[[", "1" * 400]


# -- bases -------------------------------------------------------------------------------------
def synthetic_bvh(frames: int = 8) -> str:
    names = list(MIXAMO)
    parents = [-1] + [names.index(MIXAMO_PARENT[n]) for n in names[1:]]
    rest = SMPL_REST[[MIXAMO[n] for n in names]]
    t = np.arange(frames)[:, None]
    motion = 15 * np.sin(0.3 * t + np.arange(6 + 3 * (len(names) - 1)))
    motion[:, :3] = rest[0] * 100 + np.array([0.0, 0.0, 2.0]) * t
    for arm, sign in (("LeftArm", -1), ("RightArm", 1)):
        motion[:, 6 + 3 * (names.index(arm) - 1)] += sign * 70
    return bvh_text(names, parents, rest * 100, motion, frame_time=1 / 30)


SYNTH_BONES = [  # (name, parent, direction, length) of a small CMU-like humanoid, Y up, +Z forward
    ("lhipjoint", "root", (1, -1, 0), 2.0), ("lfemur", "lhipjoint", (0, -1, 0), 7.0),
    ("ltibia", "lfemur", (0, -1, 0), 7.0), ("lfoot", "ltibia", (0, 0, 1), 2.0),
    ("rhipjoint", "root", (-1, -1, 0), 2.0), ("rfemur", "rhipjoint", (0, -1, 0), 7.0),
    ("rtibia", "rfemur", (0, -1, 0), 7.0), ("rfoot", "rtibia", (0, 0, 1), 2.0),
    ("lowerback", "root", (0, 1, 0), 2.0), ("upperback", "lowerback", (0, 1, 0), 2.0),
    ("thorax", "upperback", (0, 1, 0), 2.0), ("lowerneck", "thorax", (0, 1, 0), 1.5),
    ("upperneck", "lowerneck", (0, 1, 0), 1.5), ("head", "upperneck", (0, 1, 0), 1.5),
    ("lclavicle", "thorax", (1, 0.2, 0), 3.0), ("lhumerus", "lclavicle", (0, -1, 0), 5.0),
    ("lradius", "lhumerus", (0, -1, 0), 4.0), ("lhand", "lradius", (0, -1, 0), 1.0),
    ("rclavicle", "thorax", (-1, 0.2, 0), 3.0), ("rhumerus", "rclavicle", (0, -1, 0), 5.0),
    ("rradius", "rhumerus", (0, -1, 0), 4.0), ("rhand", "rradius", (0, -1, 0), 1.0),
]


def synthetic_asf_amc(frames: int = 6) -> tuple[str, str]:
    asf = [":version 1.10", ":name synth", ":units", "  mass 1.0", "  length 0.45", "  angle deg",
           ":documentation", "  synthetic", ":root", "  order TX TY TZ RX RY RZ", "  axis XYZ",
           "  position 0 0 0", "  orientation 0 0 0", ":bonedata"]
    for i, (name, _, d, length) in enumerate(SYNTH_BONES):
        n = np.linalg.norm(d)
        asf += ["  begin", f"     id {i + 1}", f"     name {name}",
                f"     direction {d[0] / n:.6f} {d[1] / n:.6f} {d[2] / n:.6f}", f"     length {length}",
                "     axis 0 0 0 XYZ", "    dof rx ry rz", "    limits (-180 180)", "(-180 180)", "(-180 180)",
                "  end"]
    kids: dict = {}
    for name, parent, *_ in SYNTH_BONES:
        kids.setdefault(parent, []).append(name)
    asf += [":hierarchy", "  begin"] + [f"    {p} {' '.join(c)}" for p, c in kids.items()] + ["  end"]
    amc = [":FULLY-SPECIFIED", ":DEGREES"]
    for f in range(frames):
        amc.append(str(f + 1))
        amc.append(f"root {0.1 * f:.3f} 17 {0.5 * f:.3f} 0 {2 * f} 0")
        for k, (name, *_) in enumerate(SYNTH_BONES):
            amc.append(f"{name} {10 * np.sin(f + k):.3f} {5 * np.cos(f + k):.3f} 0")
    return "\n".join(asf) + "\n", "\n".join(amc) + "\n"


def synthetic_deepmimic(frames: int = 12) -> str:
    """A 44-value humanoid3d clip: walking root, quaternions near identity, knees and elbows bent."""
    rng = np.random.default_rng(0)
    table = np.zeros((frames, 44))
    table[:, 0], table[:, 1:4] = 1 / 30, np.array([[0.03 * f, 0.85, 0.0] for f in range(frames)])
    for start in (4, 8, 12, 16, 21, 25, 30, 35, 39):
        q = np.column_stack([np.ones(frames), rng.normal(0, 0.1, (frames, 3))])
        table[:, start:start + 4] = q / np.linalg.norm(q, axis=1, keepdims=True)
    for col in (20, 29, 34, 43):
        table[:, col] = -0.3 if col in (20, 34) else 0.3
    return _deepmimic_text("none", np.round(table, 6).tolist())


def _deepmimic_text(loop: str, frames: list) -> str:
    """As DeepMimic writes them: one frame per line."""
    rows = ",\n".join("    " + json.dumps(row) for row in frames)
    return f'{{\n"Loop": "{loop}",\n"Frames":\n[\n{rows}\n]\n}}\n'


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


def _small_deepmimic(path, frames=12):
    data = json.loads(path.read_text())
    return _deepmimic_text(data.get("Loop", "none"), data["Frames"][:frames])


# -- mutations ---------------------------------------------------------------------------------
def mutate(text: str, rng: np.random.Generator) -> bytes:
    """One random corruption of a text file."""
    kind = int(rng.integers(0, 13))
    lines = text.split("\n")
    if kind == 0:  # truncate anywhere
        return text.encode()[: int(rng.integers(0, len(text)))]
    if kind == 1:  # drop lines
        for _ in range(int(rng.integers(1, 4))):
            if lines:
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
        repl = {"Frames:": ["Frames: 999999999", "Frames: 0", "Frames: -3", "Frames: 2.5", "Frames: 1e30"],
                "Frame Time:": ["Frame Time: 0", "Frame Time: -1", "Frame Time: nan", "Frame Time: 1e-9",
                                "Frame Time: 2.0", "Frame Time: 1e30"],
                "length": ["length 0", "length -1", "length 1e300"], ":DEGREES": [":RADIANS"],
                '"Loop"': ['"Loop": "wrap",', '"Loop": 5,', '"Loop": ["wrap"],']}
        for k, s in enumerate(lines):
            for key, opts in repl.items():
                if s.strip().startswith(key) and rng.random() < 0.5:
                    lines[k] = opts[int(rng.integers(0, len(opts)))]
    elif kind == 10:  # numbers scaled absurdly (durations, offsets, angles)
        scale = ["1e30", "-1e30", "0", "1e-300", "12345678"][int(rng.integers(0, 5))]
        i = int(rng.integers(0, len(lines)))
        lines[i] = " ".join((scale if t.strip(",[]").replace(".", "").replace("-", "").isdigit() else t)
                            for t in lines[i].split())
    elif kind == 11:  # a block repeated many times (many joints / frames / bones)
        i = int(rng.integers(0, len(lines)))
        j = min(len(lines), i + int(rng.integers(1, 8)))
        lines[i:i] = lines[i:j] * int(rng.integers(2, 200))
    else:  # deep nesting or a huge token spliced in
        i = int(rng.integers(0, len(lines)))
        lines[i] = lines[i] + ("[" * 5000 if rng.random() < 0.5 else " 9" * 20000)
    return "\n".join(lines).encode("utf-8", errors="replace")


@pytest.fixture(scope="module")
def bases(request):
    """{kind: [(label, text)]}; synthetic always, real clips when the archives are present."""
    asf, amc = synthetic_asf_amc()
    out = {"bvh": [("synth.bvh", synthetic_bvh())], "asf": [("synth.asf", asf)], "amc": [("synth.amc", amc)],
           "deepmimic": [("synth.txt", synthetic_deepmimic())]}
    try:
        root = request.getfixturevalue("mocap_root")
    except pytest.skip.Exception:
        if REQUIRE_DATA:
            raise
        return out, (asf, amc)
    out["bvh"] += [("bandai.bvh", _small_bvh(root / "bandai/dataset-1/data/dataset-1_walk_active_001.bvh")),
                   ("cmu.bvh", _small_bvh(root / "cmu/bvh/02/02_01.bvh"))]
    real_asf, real_amc = (root / "cmu/asfamc/02/02.asf").read_text(), _small_amc(root / "cmu/asfamc/02/02_01.amc")
    out["asf"].append(("02.asf", real_asf))
    out["amc"].append(("02_01.amc", real_amc))
    dm = sorted((root / "deepmimic").glob("humanoid3d_*.txt"))
    if dm:
        out["deepmimic"].append((dm[0].name, _small_deepmimic(dm[0])))
    return out, (real_asf, real_amc)


def test_fuzz_all_readers(bases, tmp_path):
    texts, (good_asf, good_amc) = bases
    rng = np.random.default_rng(20261122)
    cases, kinds = [], []

    def add(kind, name, data, asf=None):
        p = tmp_path / name
        p.write_bytes(data if isinstance(data, bytes) else data.encode())
        cases.append({"path": str(p), "asf": str(asf) if asf else None})
        kinds.append(kind)

    good_asf_path = tmp_path / "good.asf"
    good_asf_path.write_text(good_asf)
    # the unmutated bases first: each must load
    for kind, items in texts.items():
        for label, text in items:
            if kind == "bvh":
                add("base", f"base_{label}", text)
            elif kind == "deepmimic":
                add("base", f"base_{label}", text)
            elif kind == "amc":
                asf_text = dict(texts["asf"])["synth.asf" if label == "synth.amc" else "02.asf"]
                (tmp_path / f"base_{label}.asf").write_text(asf_text)
                add("base", f"base_{label}", text, tmp_path / f"base_{label}.asf")
    n_base = len(cases)
    for kind, items in texts.items():
        for i in range(CASES):
            label, text = items[i % len(items)]
            data = mutate(text, rng)
            if kind == "bvh":
                add(kind, f"{i:03d}_{label}", data)
            elif kind == "deepmimic":
                add(kind, f"{i:03d}_{label}", data)
            elif kind == "asf":  # a mutated skeleton with its real motion
                asf_path = tmp_path / f"{i:03d}_{label}"
                asf_path.write_bytes(data)
                amc = dict(texts["amc"])["synth.amc" if label == "synth.asf" else "02_01.amc"]
                add(kind, f"{i:03d}_{label}.amc", amc, asf_path)
            else:  # a mutated motion on its real skeleton
                asf_text = dict(texts["asf"])["synth.asf" if label == "synth.amc" else "02.asf"]
                asf_path = tmp_path / f"{i:03d}_{label}.asf"
                asf_path.write_text(asf_text)
                add(kind, f"{i:03d}_{label}", data, asf_path)
    assert len(cases) - n_base >= 500
    results = run_limited(cases, timeout_s=30, mem_bytes=GB)
    assert len(results) == len(cases)
    bad = [r for r in results if r["outcome"] not in ("ok", "ShapeMoveError")]
    assert bad == [], bad[:5]
    assert all(r["max_rss"] < GB and r["seconds"] < 30 for r in results), max(results, key=lambda r: r["max_rss"])
    assert all(r["outcome"] == "ok" for r in results[:n_base]), results[:n_base]
    for kind in texts:
        outcomes = [r["outcome"] for r, k in zip(results, kinds) if k == kind]
        assert "ShapeMoveError" in outcomes, kind  # the mutations bite...
        if kind != "asf":
            assert "ok" in outcomes, kind  # ...and some stay loadable
    assert all(r["message"] for r in results if r["outcome"] == "ShapeMoveError")


@pytest.mark.parametrize("content", [b"", b"\0" * 100, bytes(range(256)) * 8, b"HIERARCHY", b"HIERARCHY\nROOT",
                                     b"MOTION\nFrames: 1\nFrame Time: 0.1\n1 2 3", b"{" * 5000 + b"}" * 5000,
                                     b"HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
                                     + b"JOINT b\n{\nOFFSET 0 1 0\n" * 3000, b'{"Frames": ' + b"[" * 100000,
                                     b'{"Loop": "wrap", "Frames": [[0.1]]}'])
def test_garbage_files(tmp_path, content):
    for ext in (".bvh", ".amc", ".npz", ".txt"):
        p = tmp_path / f"g{ext}"
        p.write_bytes(content)
        (tmp_path / "g.asf").write_bytes(content)
        with pytest.raises(ShapeMoveError):
            load_mocap(p)
