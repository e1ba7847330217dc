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
from .limits import (MAX_BVH_BYTES, MAX_FRAME_TIME, MAX_HIERARCHY_BYTES, MAX_SECONDS, MIN_FRAME_TIME,
                     check_joint_frames, is_number, open_bounded)
from .mocap_clip import Mocap, finish_mocap
from .units_axes import UNITS

CHANNELS = {"xposition": ("p", 0), "yposition": ("p", 1), "zposition": ("p", 2),
            "xrotation": ("r", "x"), "yrotation": ("r", "y"), "zrotation": ("r", "z")}
MAX_JOINTS = 2000
MAX_VALUE = 1e7  # any channel value beyond this is corrupt (cm, degrees)
FK_WINDOW = 4096  # frames posed at once when reading (memory: the take's positions and rotations, no more)


class _Tokens:
    def __init__(self, text: str, source):
        self.tok, self.line = [], []
        for n, row in enumerate(text.splitlines(), 1):
            words = row.split()
            self.tok += words
            self.line += [n] * len(words)
        self.i = 0
        self.source = source

    def at(self) -> int:
        """Line number (1-based) of the token read last."""
        return self.line[max(0, min(self.i, len(self.line)) - 1)] if self.line else 1

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
    return _hierarchy(text, source)[:4]


def _hierarchy(text: str, source):
    """``parse_hierarchy`` + [(name, line)] of the JOINTs/ROOT that have no CHANNELS line."""
    tk = _Tokens(text, source)
    tk.expect("HIERARCHY")
    tk.expect("ROOT")
    names, parents, offsets, channels, is_end = [], [], [], [], []
    has_channels, opened = [False], [1]
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
            has_channels[cur] = True
        elif key in ("JOINT", "END"):
            where = tk.at()  # the JOINT keyword's line
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
            has_channels.append(key == "END")
            opened.append(where)
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
    missing = [(names[j], opened[j]) for j in range(len(names)) if not has_channels[j]]
    return names, np.array(parents, dtype=np.int64), np.array(offsets, dtype=np.float64), channels, missing


def _text_lines(text: str, start: int = 0):
    """The lines of ``text`` from offset ``start``, one at a time (no list of all lines in memory)."""
    pos, size = start, len(text)
    while pos < size:
        nl = text.find("\n", pos)
        nl = size if nl < 0 else nl
        yield text[pos:nl]
        pos = nl + 1


def _motion_header(lines, line_no: int, source):
    """Parse 'Frames: n' and 'Frame Time: dt' at the top of the MOTION section from the iterator
    ``lines`` (the line after MOTION is ``line_no``). Returns (n, dt, line of Frame Time, next line number)."""
    vals, at = {}, {}
    while len(vals) < 2:
        raw = next(lines, None)
        if raw is None:
            raise ShapeMoveError(f"{source}: BVH motion header needs 'Frames:' and 'Frame Time:' lines")
        s, line_no = raw.strip(), line_no + 1
        if not s:
            continue
        low = s.lower()
        key = "time" if low.startswith("frame time") else "frames" if low.startswith("frames") else None
        if key is None:
            raise ShapeMoveError(f"{source}: line {line_no - 1}: BVH motion header: expected 'Frames:'/'Frame Time:', "
                                 f"found {s[:60]!r}")
        try:
            vals[key] = float(s.split(":", 1)[1]) if ":" in s else float(s.split()[-1])
        except (ValueError, IndexError):
            raise ShapeMoveError(f"{source}: line {line_no - 1}: BVH motion header: bad line {s[:60]!r}") from None
        at[key] = line_no - 1
    return vals["frames"], vals["time"], at, line_no


def check_frame_time(dt: float, source, where: str = "") -> None:
    """Refuse a frame time no capture has (``limits.MIN_FRAME_TIME`` .. ``MAX_FRAME_TIME``): a wrong
    header would otherwise resample minutes of work and gigabytes out of a small file."""
    if not MIN_FRAME_TIME <= dt <= MAX_FRAME_TIME:
        raise ShapeMoveError(f"{source}: {where}frame time {dt:g} s ({1 / dt:.4g} fps) is implausible for motion "
                             f"capture (allowed {MIN_FRAME_TIME * 1000:g} ms to {MAX_FRAME_TIME:g} s): the header is "
                             "probably wrong; pass --source-fps N to read the frames at N per second")


def parse_bvh(text: str, source="BVH", frame_time: float | None = None):
    """BVH text -> (names, parents, offsets (J,3), channels, data (T,C), frame_time). Strict: every
    data row holds exactly the declared channels' values, the rows number exactly 'Frames:', every
    JOINT has a CHANNELS line, and the frame time is plausible (``frame_time`` overrides it)."""
    cut = text.find("MOTION")
    if cut < 0:
        raise ShapeMoveError(f"{source}: not a BVH file (no MOTION section)")
    return _parse(text[:cut], _text_lines(text, cut + len("MOTION")), source, frame_time, len(text) - cut)


def _parse(head: str, lines, source, frame_time: float | None, data_bytes: int):
    """The hierarchy text ``head`` and an iterator over the lines after 'MOTION' (``data_bytes``
    long) -> parse_bvh's tuple."""
    if len(head) > MAX_HIERARCHY_BYTES:
        raise ShapeMoveError(f"{source}: BVH hierarchy is {len(head) / 2**20:.0f} MB, larger than any skeleton "
                             f"({MAX_HIERARCHY_BYTES // 2**20} MB)")
    names, parents, offsets, channels, missing = _hierarchy(head, source)
    line_no = head.count("\n") + 1  # the MOTION line
    frames, dt, at, line_no = _motion_header(lines, line_no, source)
    C = sum(len(c) for c in channels)
    if not (np.isfinite(frames) and frames == int(frames) and frames >= 1):
        raise ShapeMoveError(f"{source}: line {at['frames']}: BVH says {frames} frames")
    if not (np.isfinite(dt) and dt > 0):
        raise ShapeMoveError(f"{source}: line {at['time']}: BVH frame time {dt} is not positive")
    frames = int(frames)
    if C == 0:
        raise ShapeMoveError(f"{source}: BVH has no channels")
    check_joint_frames(frames, len(names), source, "BVH")  # before allocating anything per frame
    if frames * C > data_bytes // 2 + 1:  # each value needs at least a digit and a separator
        raise ShapeMoveError(f"{source}: BVH is truncated: 'Frames: {frames}' (line {at['frames']}) of {C} channels, "
                             f"the file holds at most {(data_bytes // 2 + 1) // C} rows")
    step = float(frame_time) if frame_time is not None else dt
    if (frames - 1) * step > MAX_SECONDS:
        raise ShapeMoveError(f"{source}: the clip lasts {(frames - 1) * step:,.0f} s ({frames:,} frames of "
                             f"{step:g} s), longer than {MAX_SECONDS:.0f} s: wrong frame time in the file, or split the clip")
    if frame_time is None:
        check_frame_time(dt, source, f"line {at['time']}: BVH ")
    if missing:
        name, where = missing[0]
        raise ShapeMoveError(f"{source}: line {where}: BVH joint {name!r} has no CHANNELS line (every JOINT needs "
                             "one, 'CHANNELS 0' if it never moves): its values would be read as another joint's")
    data = np.empty((frames, C), dtype=np.float64)
    row = 0
    for raw in lines:
        line_no += 1
        toks = raw.split()
        if not toks:
            continue
        if row >= frames:
            raise ShapeMoveError(f"{source}: line {line_no - 1}: BVH holds more data rows than its 'Frames: {frames}' "
                                 f"(line {at['frames']}) says: the Frames line is wrong or rows were added")
        if len(toks) != C:
            raise ShapeMoveError(f"{source}: line {line_no - 1}: BVH data row {row + 1} has {len(toks)} values, the "
                                 f"hierarchy declares {C} channels: a value was added or lost, or a CHANNELS line "
                                 "is wrong (reading on would shift every value after it)")
        try:
            data[row] = np.array(toks, dtype=np.float64)
        except ValueError:
            bad = next(t for t in toks if not is_number(t))
            raise ShapeMoveError(f"{source}: line {line_no - 1}: BVH motion data contains something that is not a "
                                 f"number: {bad[:40]!r}") from None
        row += 1
    if row < frames:
        raise ShapeMoveError(f"{source}: BVH is truncated: 'Frames: {frames}' (line {at['frames']}) but the file "
                             f"holds {row} data rows")
    if not np.all(np.isfinite(data)) or np.abs(data).max() > MAX_VALUE:
        raise ShapeMoveError(f"{source}: BVH motion data holds NaN, inf or absurdly large values")
    return names, parents, offsets, channels, data, step


def _file_lines(fh, first: bytes):
    """Decoded lines of the binary file ``fh`` after ``first`` (the rest of the MOTION line)."""
    yield first.decode("utf-8", errors="replace")
    for raw in fh:
        yield raw.decode("utf-8", errors="replace")


def read_bvh(path, frame_time: float | None = None):
    """``parse_bvh`` of the file ``path``, streamed: the hierarchy (at most ``MAX_HIERARCHY_BYTES``)
    is read whole, the data rows one line at a time, so the file's size (at most ``MAX_BVH_BYTES``)
    never sits in memory, only the (T,C) values."""
    path = Path(path)
    with open_bounded(path, MAX_BVH_BYTES, "BVH", "split the clip") as fh:
        start = fh.read(4096)
        if b"\0" in start:
            raise ShapeMoveError(f"{path}: binary data, not an BVH text file")
        head = start + fh.read(MAX_HIERARCHY_BYTES + 64 - len(start))
        cut = head.find(b"MOTION")
        if cut < 0:
            if len(head) > MAX_HIERARCHY_BYTES:
                raise ShapeMoveError(f"{path}: BVH hierarchy is larger than any skeleton "
                                     f"({MAX_HIERARCHY_BYTES // 2**20} MB)")
            raise ShapeMoveError(f"{path}: not a BVH file (no MOTION section)")
        fh.seek(cut + len("MOTION"))
        first = fh.readline()
        size = path.stat().st_size
        return _parse(head[:cut].decode("utf-8", errors="replace"), _file_lines(fh, first), path, frame_time,
                      size - cut)


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


def load_bvh(path, unit: str | None = None, up_axis: str | None = None, fps: float | None = None) -> Mocap:
    """Read a BVH file into a Mocap (metres, Y up). ``unit`` ('m', 'cm', 'mm', 'inch') and
    ``up_axis`` ('Y', 'Z') override the detection; ``fps`` the file's Frame Time (one whose
    header is implausible is refused unless ``fps`` is given)."""
    path = Path(path)
    if fps is not None and not (np.isfinite(fps) and 1.0 / MAX_FRAME_TIME <= fps <= 1.0 / MIN_FRAME_TIME):
        raise ShapeMoveError(f"source frame rate {fps} must lie between {1 / MAX_FRAME_TIME:g} and "
                             f"{1 / MIN_FRAME_TIME:g} fps")
    names, parents, offsets, channels, data, dt = read_bvh(path, None if fps is None else 1.0 / fps)
    T, J = len(data), len(names)
    positions, rots = np.empty((T, J, 3)), np.empty((T, J, 3, 3))
    for s in range(0, T, FK_WINDOW):  # per frame: the same numbers, without whole-take temporaries
        trans, rots[s:s + FK_WINDOW] = bvh_local_transforms(offsets, channels, data[s:s + FK_WINDOW])
        positions[s:s + FK_WINDOW] = forward_kinematics(rots[s:s + FK_WINDOW], joints_from_offsets(trans, parents),
                                                        parents)[0]
    del data
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
