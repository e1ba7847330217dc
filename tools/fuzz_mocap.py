"""Fuzz the mocap readers with damaged REAL files; count what goes wrong (issue 28).

    .venv/bin/python tools/fuzz_mocap.py [--cases 480] [--seed 0] [--json OUT]

Bases: short real clips from the shared archives (Bandai BVH, CMU BVH, CMU and HDM05 ASF/AMC).
Each case damages one base in one way a file really gets damaged (a value added to or lost from a
row or bone line, a CHANNELS line lost or miscounted, the Frames count off, an absurd frame time,
rows dropped/duplicated/joined/split, truncation, a garbage token, radians declared over degrees,
a dof lost from the ASF, a frame number lost), or changes it harmlessly (CRLF line ends, tabs,
trailing spaces, blank or comment lines: it must load the same), and is read by ``load_smpl22`` in its OWN forked
process limited to 30 s and 1 GB more address space. Outcomes:

  refused      ShapeMoveError (a sentence for the user)            -- fine
  same         loaded, every joint within 1 cm of the intact clip  -- fine (the damage was harmless)
  shorter      loaded fewer frames, each within 1 cm of the intact clip's -- fine: a file cut between
               two frames is a valid shorter file (AMC files carry no frame count)
  silent-wrong loaded, but some joint is >= 1 cm off the intact clip (or the length differs)
  traceback    any other exception
  hang         killed by the 30 s alarm
  over-memory  MemoryError, or killed past the 1 GB limit

Prints the counts and one line per finding; exit status 1 when anything but refused/same/shorter occurs.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import resource
import signal
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

TIMEOUT_S = 30
MEM_BYTES = 1 << 30
TOLERANCE_M = 0.01
BAD_TOKENS = ["nan", "inf", "-inf", "1e400", "abc", "{", "}", "1,5", "0x1F", "--1", "1e-400x", "CHANNELS", "MOTION"]


# -- bases ---------------------------------------------------------------------------------------
def _cut_bvh(text: str, frames: int) -> str:
    lines = text.splitlines()
    k = next(i for i, s in enumerate(lines) if s.strip().lower().startswith("frame time")) + 1
    rows = [s for s in lines[k:] if s.strip()][:frames]
    head = [re.sub(r"(?i)^(\s*frames:).*", rf"\g<1> {len(rows)}", s) for s in lines[:k]]
    return "\n".join(head + rows) + "\n"


def _cut_amc(text: str, frames: int) -> str:
    lines = text.splitlines()
    starts = [i for i, s in enumerate(lines) if s.strip().isdigit()]
    end = starts[frames] if len(starts) > frames else len(lines)
    return "\n".join(lines[:end]) + "\n"


def bases(root: Path) -> list[dict]:
    """[{name, kind, files {name: text}, main}] short real clips (a few seconds each)."""
    out = []
    for rel, frames in (("bandai/dataset-2/data/dataset-2_walk_masculine_003.bvh", 120),
                        ("bandai/dataset-1/data/dataset-1_run_happy_001.bvh", 90),
                        ("cmu/bvh/02/02_01.bvh", 360)):
        p = root / rel
        if p.is_file():
            out.append({"name": p.name, "kind": "bvh", "main": p.name,
                        "files": {p.name: _cut_bvh(p.read_text(errors="replace"), frames)}})
    for asf, amc in (("cmu/asfamc/02/02.asf", "cmu/asfamc/02/02_01.amc"),
                     ("hdm05/bd/HDM_bd.asf", "hdm05/bd/HDM_bd_kickLFront1Reps_001_120.amc")):
        a, m = root / asf, root / amc
        if not (a.is_file() and m.is_file()):
            continue
        out.append({"name": m.name, "kind": "amc", "main": m.name,
                    "files": {a.name: a.read_text(errors="replace"), m.name: _cut_amc(m.read_text(errors="replace"), 360)}})
    return out


# -- mutations -----------------------------------------------------------------------------------
def _data_rows(lines):
    k = next(i for i, s in enumerate(lines) if s.strip().lower().startswith("frame time")) + 1
    return [i for i in range(k, len(lines)) if lines[i].strip()]


def _bone_lines(lines):
    first = next(i for i, s in enumerate(lines) if s.strip().isdigit())
    return [i for i in range(first, len(lines)) if lines[i].strip() and not lines[i].strip().isdigit()]


def mutate_bvh(text: str, kind: str, rng) -> str:
    lines = text.splitlines()
    rows = _data_rows(lines)
    r = rows[int(rng.integers(len(rows)))]
    if kind == "row_plus":
        lines[r] += f" {rng.normal(0, 30):.4f}"
    elif kind == "row_minus":
        toks = lines[r].split()
        del toks[int(rng.integers(len(toks)))]
        lines[r] = " ".join(toks)
    elif kind == "del_channels":
        ch = [i for i, s in enumerate(lines) if "CHANNELS" in s]
        del lines[ch[int(rng.integers(len(ch)))]]
    elif kind == "channels_count":
        ch = [i for i, s in enumerate(lines) if "CHANNELS" in s]
        i = ch[int(rng.integers(len(ch)))]
        toks = lines[i].split()
        n = int(toks[1])
        drop = int(rng.integers(1, n)) if n > 1 else 0
        lines[i] = " ".join(["CHANNELS", str(n - drop)] + toks[2:2 + n - drop]) if drop else lines[i] + " Xrotation"
    elif kind == "frames_off":
        d = int(rng.choice([-50, -3, -1, 1, 3, 50]))
        lines = [re.sub(r"(?i)^(\s*frames:\s*)(\d+)", lambda m: f"{m.group(1)}{int(m.group(2)) + d}", s) for s in lines]
    elif kind == "frame_time":
        v = rng.choice(["2.0", "5", "0.00001", "0", "-1", "nan", "1e30"])
        lines = [re.sub(r"(?i)^(\s*frame time:).*", rf"\g<1> {v}", s) for s in lines]
    elif kind == "drop_row":
        del lines[r]
    elif kind == "dup_row":
        lines.insert(r, lines[r])
    elif kind == "join_rows":
        if r + 1 < len(lines):
            lines[r] = lines[r] + " " + lines.pop(r + 1)
    elif kind == "split_row":
        toks = lines[r].split()
        c = int(rng.integers(1, len(toks)))
        lines[r:r + 1] = [" ".join(toks[:c]), " ".join(toks[c:])]
    elif kind == "truncate":
        body = "\n".join(lines)
        return body[:int(rng.integers(len(body) // 3, len(body) - 1))]
    elif kind == "garbage":
        toks = lines[r].split()
        toks[int(rng.integers(len(toks)))] = BAD_TOKENS[int(rng.integers(len(BAD_TOKENS)))]
        lines[r] = " ".join(toks)
    elif kind == "harmless":  # what editors and exporters do to a good file: it must still load the same
        how = int(rng.integers(4))
        if how == 0:
            return "\r\n".join(lines) + "\r\n"
        if how == 1:
            lines = [s.replace(" ", "\t") if i in set(rows) else s for i, s in enumerate(lines)]
        elif how == 2:
            lines = [s + "   " for s in lines]
        else:
            lines.insert(r, "")
            lines.append("")
    return "\n".join(lines) + "\n"


def mutate_amc(files: dict, main: str, kind: str, rng) -> dict:
    out = dict(files)
    asf_name = next(n for n in files if n.lower().endswith(".asf"))
    lines = files[main].splitlines()
    bl = _bone_lines(lines)
    r = bl[int(rng.integers(len(bl)))]
    if kind == "bone_plus":
        lines[r] += f" {rng.normal(0, 20):.4f}"
    elif kind == "bone_minus":
        toks = lines[r].split()
        if len(toks) > 1:
            del toks[int(rng.integers(1, len(toks)))]
        lines[r] = " ".join(toks)
    elif kind == "drop_bone_line":
        del lines[r]
    elif kind == "dup_bone_line":
        lines.insert(r, lines[r])
    elif kind == "drop_frame_number":
        nums = [i for i, s in enumerate(lines) if s.strip().isdigit()]
        del lines[nums[int(rng.integers(1, len(nums)))]]
    elif kind == "amc_radians":
        lines = [":RADIANS" if s.strip().upper().startswith(":DEGREES") else s for s in lines]
        if not any(s.strip().upper().startswith(":RADIANS") for s in lines):
            lines.insert(0, ":RADIANS")
    elif kind == "asf_radians":
        out[asf_name] = files[asf_name].replace("angle deg", "angle rad")
    elif kind == "asf_dof_lost":
        a = files[asf_name].splitlines()
        dof = [i for i, s in enumerate(a) if s.strip().startswith("dof") and len(s.split()) > 2]
        i = dof[int(rng.integers(len(dof)))]
        toks = a[i].split()
        del toks[int(rng.integers(1, len(toks)))]
        a[i] = "    " + " ".join(toks)
        out[asf_name] = "\n".join(a) + "\n"
    elif kind == "truncate":
        body = "\n".join(lines)
        out[main] = body[:int(rng.integers(len(body) // 3, len(body) - 1))]
        return out
    elif kind == "garbage":
        toks = lines[r].split()
        toks[int(rng.integers(1, len(toks))) if len(toks) > 1 else 0] = BAD_TOKENS[int(rng.integers(len(BAD_TOKENS)))]
        lines[r] = " ".join(toks)
    elif kind == "harmless":  # line endings, comments, spacing: still the same clip
        how = int(rng.integers(3))
        if how == 0:
            out[main] = "\r\n".join(lines) + "\r\n"
            return out
        if how == 1:
            lines.insert(r, "# a comment line")
        else:
            lines = [s.replace(" ", "  ") + " " for s in lines]
    out[main] = "\n".join(lines) + "\n"
    return out


BVH_KINDS = ["row_plus", "row_minus", "del_channels", "channels_count", "frames_off", "frame_time", "drop_row",
             "dup_row", "join_rows", "split_row", "truncate", "garbage", "harmless"]
AMC_KINDS = ["bone_plus", "bone_minus", "drop_bone_line", "dup_bone_line", "drop_frame_number", "amc_radians",
             "asf_radians", "asf_dof_lost", "truncate", "garbage", "harmless"]


# -- one limited load ----------------------------------------------------------------------------
def _vm_bytes() -> int:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")


def _load_joints(path: Path) -> np.ndarray:
    from shapemove.core.io.mocap import load_smpl22

    return np.asarray(load_smpl22(path).joints, dtype=np.float64)


def run_case(path: Path, intact: np.ndarray | None) -> dict:
    """Load ``path`` in a forked child under the limits; classify against ``intact`` joints."""
    rfd, wfd = os.pipe()
    t0 = time.perf_counter()
    pid = os.fork()
    if pid == 0:  # the child: limits, load, one JSON line back
        os.close(rfd)
        limit = _vm_bytes() + MEM_BYTES
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        signal.alarm(TIMEOUT_S)
        from shapemove.core.errors import ShapeMoveError

        try:
            j = _load_joints(path)
            if intact is not None and 0 < j.shape[0] < intact.shape[0] and j.shape[1:] == intact.shape[1:] \
                    and float(np.linalg.norm(j - intact[:len(j)], axis=-1).max()) < TOLERANCE_M:
                out = {"outcome": "shorter", "message": f"a valid shorter file: {j.shape[0]} frames of "
                                                        f"{intact.shape[0]}, each within 1 cm of the intact clip's"}
            elif intact is None or j.shape != intact.shape:
                out = {"outcome": "silent-wrong", "message": f"{j.shape[0]} frames, the intact clip "
                                                             f"{None if intact is None else intact.shape[0]}"}
            else:
                err = float(np.linalg.norm(j - intact, axis=-1).max())
                out = {"outcome": "same" if err < TOLERANCE_M else "silent-wrong",
                       "message": f"joints up to {100 * err:.1f} cm off the intact clip"}
        except ShapeMoveError as exc:
            out = {"outcome": "refused", "message": str(exc)[:300]}
        except MemoryError:
            out = {"outcome": "over-memory", "message": "MemoryError"}
        except BaseException as exc:  # noqa: BLE001  anything else is a finding
            out = {"outcome": "traceback", "message": f"{type(exc).__name__}: {str(exc)[:300]}"}
        os.write(wfd, json.dumps(out).encode())
        os._exit(0)
    os.close(wfd)
    with os.fdopen(rfd, "rb") as fh:
        raw = fh.read()
    _, status = os.waitpid(pid, 0)
    res = json.loads(raw) if raw else None
    if res is None:
        sig = os.WTERMSIG(status) if os.WIFSIGNALED(status) else None
        res = {"outcome": "hang" if sig == signal.SIGALRM else "over-memory" if sig in (signal.SIGKILL, signal.SIGSEGV)
               else "traceback", "message": f"child ended with status {status} (signal {sig})"}
    res["seconds"] = round(time.perf_counter() - t0, 2)
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=480)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--verbose", action="store_true", help="one example message per kind of damage")
    args = ap.parse_args(argv)
    from shapemove.core.io.archive import mocap_root

    # import the readers once, before forking: each child only reads
    import shapemove.core.io.mocap  # noqa: F401

    base = bases(mocap_root())
    if not base:
        print("no mocap archives found", file=sys.stderr)
        return 2
    rng = np.random.default_rng(args.seed)
    counts: dict = {}
    findings = []
    by_kind: dict = {}
    example: dict = {}  # one message per kind of damage
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        intact = {}
        for b in base:
            d = tmp / "intact" / b["name"]
            d.mkdir(parents=True)
            for n, t in b["files"].items():
                (d / n).write_text(t)
            intact[b["name"]] = _load_joints(d / b["main"])
        for i in range(args.cases):
            b = base[i % len(base)]
            kinds = BVH_KINDS if b["kind"] == "bvh" else AMC_KINDS
            kind = kinds[(i // len(base)) % len(kinds)]
            d = tmp / f"case{i:04d}"
            d.mkdir()
            files = ({b["main"]: mutate_bvh(b["files"][b["main"]], kind, rng)} if b["kind"] == "bvh"
                     else mutate_amc(b["files"], b["main"], kind, rng))
            for n, t in files.items():
                (d / n).write_text(t)
            res = run_case(d / b["main"], intact[b["name"]])
            counts[res["outcome"]] = counts.get(res["outcome"], 0) + 1
            by_kind.setdefault(kind, {}).setdefault(res["outcome"], 0)
            by_kind[kind][res["outcome"]] += 1
            example.setdefault(kind, f"{b['name']}: {res['message']}")
            if res["outcome"] not in ("refused", "same", "shorter"):
                findings.append({"case": i, "base": b["name"], "kind": kind, **res})
            for n in files:
                (d / n).unlink()
            d.rmdir()
    total = sum(counts.values())
    print(f"{total} damaged real files ({len(base)} bases): " + ", ".join(
        f"{k} {counts.get(k, 0)}" for k in ("refused", "same", "shorter", "silent-wrong", "traceback", "hang",
                                            "over-memory")))
    for k, v in sorted(by_kind.items()):
        print(f"  {k:18s} " + ", ".join(f"{o} {n}" for o, n in sorted(v.items())))
        if args.verbose:
            print(f"      e.g. {example[k][:220]}")
    for f in findings:
        print(f"  FINDING case {f['case']} {f['base']} {f['kind']}: {f['outcome']}: {f['message']}")
    if args.json:
        from shapemove.core.atomic import atomic_write_json

        atomic_write_json(args.json, {"counts": counts, "by_kind": by_kind, "findings": findings})
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
