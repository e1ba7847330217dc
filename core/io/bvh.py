"""BVH reader: any channel count and rotation order per joint, End Sites, position channels on
any joint (Bandai has 6 on every joint), unit and up axis detected from the skeleton.

Position channels REPLACE the matching OFFSET component (Bandai's Spine channels carry its offset;
its Hips channels carry the world position), rotation channels compose in the listed order
(``Zrotation Xrotation Yrotation`` -> Rz @ Rx @ Ry). End Sites become joints ``<parent>_End``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from ..geometry.fk import forward_kinematics, joints_from_offsets
from ..geometry.rotations import axis_rotation
from .limits import MAX_HIERARCHY_BYTES, check_joint_frames, parse_floats, read_text
from .mocap_clip import Mocap, finish_mocap
from .units_axes import UNITS

CHANNELS = {"xposition": ("p", 0), "yposition": ("p", 1), "zposition": ("p", 2),
            "xrotation": ("r", "x"), "yrotation": ("r", "y"), "zrotation": ("r", "z")}
MAX_JOINTS = 2000
MAX_VALUE = 1e7  # any channel value beyond this is corrupt (cm, degrees)


class _Tokens:
    def __init__(self, text: str, source):
        self.tok = text.split()
        self.i = 0
        self.source = source

    def next(self, what: str) -> str:
        if self.i >= len(self.tok):
            raise ShapeMoveError(f"{self.source}: BVH hierarchy ends early (expected {what})")
        t = self.tok[self.i]
        self.i += 1
        return t

    def expect(self, word: str):
        t = self.next(word)
        if t.upper() != word.upper():
            raise ShapeMoveError(f"{self.source}: BVH hierarchy: expected {word!r}, found {t[:40]!r}")

    def number(self, what: str) -> float:
        t = self.next(what)
        try:
            v = float(t)
        except ValueError:
            raise ShapeMoveError(f"{self.source}: BVH hierarchy: {what} is not a number: {t[:40]!r}") from None
        if not np.isfinite(v) or abs(v) > MAX_VALUE:
            raise ShapeMoveError(f"{self.source}: BVH hierarchy: {what} is not a finite number: {t[:40]!r}")
        return v

    def name_until_brace(self, what: str) -> str:
        parts = []
        while True:
            t = self.next(f"'{{' after {what}")
            if t == "{":
                break
            if t in ("}", "OFFSET", "CHANNELS", "JOINT") or len(parts) > 8:
                raise ShapeMoveError(f"{self.source}: BVH hierarchy: bad {what} name near {t[:40]!r}")
            parts.append(t)
        return " ".join(parts)


def parse_hierarchy(text: str, source="BVH"):
    """HIERARCHY text -> (names, parents, offsets (J,3), channels: list of per-joint channel
    lists). Iterative (no recursion), so deep or malformed nesting cannot blow the stack."""
    tk = _Tokens(text, source)
    tk.expect("HIERARCHY")
    tk.expect("ROOT")
    names, parents, offsets, channels, is_end = [], [], [], [], []
    stack = []  # open joints (indices)
    root_name = tk.name_until_brace("ROOT")
    names.append(root_name)
    taken = {root_name}
    parents.append(-1)
    stack.append(0)
    offsets.append(None)
    channels.append([])
    is_end.append(False)
    while stack:
        t = tk.next("'}'")
        cur = stack[-1]
        key = t.upper()
        if key == "}":
            j = stack.pop()
            if offsets[j] is None:
                raise ShapeMoveError(f"{source}: BVH joint {names[j]!r} has no OFFSET")
        elif key == "OFFSET":
            if offsets[cur] is not None:
                raise ShapeMoveError(f"{source}: BVH joint {names[cur]!r} has two OFFSETs")
            offsets[cur] = [tk.number("OFFSET") for _ in range(3)]
        elif key == "CHANNELS":
            if is_end[cur]:
                raise ShapeMoveError(f"{source}: BVH End Site cannot have CHANNELS")
            n = tk.number("CHANNELS count")
            if n != int(n) or not 0 <= n <= 6:
                raise ShapeMoveError(f"{source}: BVH joint {names[cur]!r}: bad channel count {n}")
            chans = []
            for _ in range(int(n)):
                c = tk.next("channel name").lower()
                if c not in CHANNELS:
                    raise ShapeMoveError(f"{source}: BVH joint {names[cur]!r}: unknown channel {c[:40]!r}")
                chans.append(c)
            if len(set(chans)) != len(chans):
                raise ShapeMoveError(f"{source}: BVH joint {names[cur]!r}: repeated channel")
            channels[cur] = chans
        elif key in ("JOINT", "END"):
            if is_end[cur]:
                raise ShapeMoveError(f"{source}: BVH End Site cannot have children")
            if key == "END":
                label = tk.name_until_brace("End Site")
                name = names[cur] + "_End" if label.lower() in ("site", "") else label
                if name in taken:
                    name = f"{name}{len(names)}"
            else:
                name = tk.name_until_brace("JOINT")
            if len(names) >= MAX_JOINTS:
                raise ShapeMoveError(f"{source}: BVH has more than {MAX_JOINTS} joints")
            names.append(name)
            taken.add(name)
            parents.append(cur)
            offsets.append(None)
            channels.append([])
            is_end.append(key == "END")
            stack.append(len(names) - 1)
        else:
            raise ShapeMoveError(f"{source}: BVH hierarchy: unexpected {t[:40]!r} in joint {names[cur]!r}")
    if tk.i != len(tk.tok):
        raise ShapeMoveError(f"{source}: BVH hierarchy: unexpected text after the ROOT block "
                             f"({tk.tok[tk.i][:40]!r}; only one ROOT is supported)")
    return names, np.array(parents, dtype=np.int64), np.array(offsets, dtype=np.float64), channels


def _motion_header(motion: str, source):
    """Parse 'Frames: n' and 'Frame Time: dt' at the top of the MOTION section.
    Returns (n, dt, the text after those two lines)."""
    vals, pos = {}, 0
    while len(vals) < 2:
        if pos >= len(motion):
            raise ShapeMoveError(f"{source}: BVH motion header needs 'Frames:' and 'Frame Time:' lines")
        nl = motion.find("\n", pos)
        nl = len(motion) if nl < 0 else nl
        s, pos = motion[pos:nl].strip(), nl + 1
        if not s:
            continue
        low = s.lower()
        key = "time" if low.startswith("frame time") else "frames" if low.startswith("frames") else None
        if key is None:
            raise ShapeMoveError(f"{source}: BVH motion header: expected 'Frames:'/'Frame Time:', found {s[:60]!r}")
        try:
            vals[key] = float(s.split(":", 1)[1]) if ":" in s else float(s.split()[-1])
        except (ValueError, IndexError):
            raise ShapeMoveError(f"{source}: BVH motion header: bad line {s[:60]!r}") from None
    return vals["frames"], vals["time"], motion[pos:]


def parse_bvh(text: str, source="BVH"):
    """BVH text -> (names, parents, offsets (J,3), channels, data (T,C), frame_time)."""
    head, sep, motion = text.partition("MOTION")
    if not sep:
        raise ShapeMoveError(f"{source}: not a BVH file (no MOTION section)")
    if len(head) > MAX_HIERARCHY_BYTES:
        raise ShapeMoveError(f"{source}: BVH hierarchy is {len(head) / 2**20:.0f} MB, larger than any skeleton "
                             f"({MAX_HIERARCHY_BYTES // 2**20} MB)")
    names, parents, offsets, channels = parse_hierarchy(head, source)
    del head
    frames, dt, body = _motion_header(motion, source)
    del motion
    C = sum(len(c) for c in channels)
    if not (np.isfinite(frames) and frames == int(frames) and frames >= 1):
        raise ShapeMoveError(f"{source}: BVH says {frames} frames")
    if not (np.isfinite(dt) and dt > 0):
        raise ShapeMoveError(f"{source}: BVH frame time {dt} is not positive")
    frames = int(frames)
    if C == 0:
        raise ShapeMoveError(f"{source}: BVH has no channels")
    check_joint_frames(frames, len(names), source, "BVH")  # before allocating anything per frame
    if frames * C > len(body) // 2 + 1:  # each value needs at least a digit and a separator
        raise ShapeMoveError(f"{source}: BVH is truncated: header says {frames} frames of {C} channels, "
                             f"the file holds at most {(len(body) // 2 + 1) // C}")
    data = parse_floats(body, frames * C, source, "BVH motion data")
    if data.size < frames * C:
        if data.size % C:
            raise ShapeMoveError(f"{source}: BVH motion data has {data.size} values, not a whole number of "
                                 f"frames of {C} channels (truncated file or wrong channel count)")
        raise ShapeMoveError(f"{source}: BVH is truncated: header says {frames} frames, data holds {data.size // C}")
    data = data.reshape(frames, C)
    if not np.all(np.isfinite(data)) or np.abs(data).max() > MAX_VALUE:
        raise ShapeMoveError(f"{source}: BVH motion data holds NaN, inf or absurdly large values")
    return names, parents, offsets, channels, data, float(dt)


def bvh_local_transforms(offsets, channels, data):
    """Per-joint local translations (T,J,3) and rotations (T,J,3,3) from the channel data (T,C)."""
    T, J = data.shape[0], len(channels)
    trans = np.broadcast_to(offsets, (T, J, 3)).copy()
    rots = np.broadcast_to(np.eye(3), (T, J, 3, 3)).copy()
    col = 0
    for j, chans in enumerate(channels):
        R = None
        for c in chans:
            kind, ax = CHANNELS[c]
            if kind == "p":
                trans[:, j, ax] = data[:, col]
            else:
                r = axis_rotation(ax, np.radians(data[:, col]))
                R = r if R is None else R @ r
            col += 1
        if R is not None:
            rots[:, j] = R
    return trans, rots


def load_bvh(path, unit: str | None = None, up_axis: str | None = None) -> Mocap:
    """Read a BVH file into a Mocap (metres, Y up). ``unit`` ('m', 'cm', 'mm', 'inch') and
    ``up_axis`` ('Y', 'Z') override the detection."""
    path = Path(path)
    text = read_text(path, "BVH")
    names, parents, offsets, channels, data, dt = parse_bvh(text, path)
    trans, rots = bvh_local_transforms(offsets, channels, data)
    positions = forward_kinematics(rots, joints_from_offsets(trans, parents), parents)[0]
    scale = None
    if unit is not None:
        if unit not in UNITS:
            raise ShapeMoveError(f"unknown unit {unit!r}; use one of {', '.join(UNITS)}")
        scale = UNITS[unit]
    return finish_mocap(names, parents, offsets, positions, 1.0 / dt, str(path), rotations=rots, unit=unit,
                        scale=scale, up_axis=up_axis, subject=_subject(path),
                        meta={"channels": channels})


def _subject(path: Path) -> str:
    """Bandai: one performer proportion ('bandai'); CMU 'NN_MM.bvh': subject 'NN'; else folder."""
    stem = path.stem
    if stem.startswith("dataset-"):
        return "bandai"
    head = stem.split("_")[0]
    return head if head.isdigit() else path.parent.name
