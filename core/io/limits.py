"""Bounds for reading untrusted motion files (BVH, ASF/AMC, DeepMimic, resampling), checked BEFORE
anything is allocated, so a small hostile file cannot ask for gigabytes or hours.

The limits sit far above any real capture: the longest clip of CMU/HDM05/Bandai is ~36,000 frames
(5 min at 120 fps) on ~40 joints (1.4 M joint-frames); a limit of 2 M joint-frames keeps every
reader's peak memory well under 1 GB (the readers hold ~6 float64 (T,J,3,3) arrays at most).

Every user file (motion text, JSON preset or config, model manifest, dataset meta) is bounded the
same way: ``check_file_size`` before reading, then ``read_bounded`` reads at most ``max_bytes + 1``
bytes, so a FIFO, a /proc file or a file that grows after the check is refused too, in the same words.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError

MAX_TEXT_BYTES = 64 * 2**20  # a motion text file larger than this is refused (largest real: ~10 MB)
MAX_BVH_BYTES = 256 * 2**20  # a BVH (streamed row by row): a 10-minute 120 fps take of a 48-joint rig is ~150 MB
MAX_AMC_BYTES = 256 * 2**20  # an AMC (streamed line by line): a 10-minute 120 fps HDM05 take is ~90 MB
MIN_FRAME_TIME = 1e-4  # s (10,000 fps): a shorter frame time is a broken header
MAX_FRAME_TIME = 1.0   # s (1 fps): a longer one too (a 2 s frame time turned an 8-minute take into gigabytes)
MAX_JOINT_FRAMES = 2_000_000  # frames x joints of one clip, before and after resampling
MAX_SECONDS = 3600.0  # one hour of motion
MAX_HIERARCHY_BYTES = 4 * 2**20  # a skeleton description (BVH HIERARCHY, ASF) larger than this is refused
_CHUNK = 1 << 20


def _amount(n: int) -> str:
    return f"{n:,} bytes" if n < 2**20 else f"{n / 2**20:,.1f} MB".replace(".0 MB", " MB")


def check_file_size(path, max_bytes: int, what: str, advice: str = "") -> int:
    """The size of the user's file ``path`` in bytes, refused (ShapeMoveError) when it is larger than
    ``max_bytes``: the one size check made BEFORE a user file is read. The message names the file,
    both sizes and ``what`` it was meant to be ('PATH: the BVH file is 80 MB; BVH files larger than
    64 MB are refused (ADVICE)'); a file that cannot be stat'ed is 'cannot read WHAT PATH: ...'."""
    path = Path(path)
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise ShapeMoveError(f"cannot read {what} {path}: {exc.strerror or exc}") from None
    if size > max_bytes:
        have, limit = _amount(size), _amount(max_bytes)
        if have == limit:  # 64 MB + a few bytes: say it in bytes
            have, limit = f"{size:,} bytes", f"{max_bytes:,} bytes"
        raise ShapeMoveError(f"{path}: the {what} file is {have}; {what} files larger than {limit} are refused"
                             + (f" ({advice})" if advice else ""))
    return size


def open_bounded(path, max_bytes: int, what: str, advice: str = ""):
    """The user's file ``path`` opened for binary reading, its size checked first (``check_file_size``);
    a file that cannot be opened is 'cannot read WHAT PATH: ...'. For readers that stream the file."""
    path = Path(path)
    check_file_size(path, max_bytes, what, advice)
    try:
        return open(path, "rb")
    except OSError as exc:
        raise ShapeMoveError(f"cannot read {what} {path}: {exc.strerror or exc}") from None


def read_bounded(path, max_bytes: int, what: str, advice: str = "") -> bytes:
    """The bytes of the user's file ``path``, at most ``max_bytes``: the size is checked before
    reading (``check_file_size``) and at most ``max_bytes + 1`` bytes are read, so a file whose
    size says less than it holds (a FIFO, a /proc file, a file that grows while read) is refused
    too ('PATH: the WHAT file is more than LIMIT ...; WHAT files larger than LIMIT are refused')."""
    path = Path(path)
    check_file_size(path, max_bytes, what, advice)
    try:
        with open(path, "rb") as fh:
            raw = fh.read(max_bytes + 1)
    except OSError as exc:
        raise ShapeMoveError(f"cannot read {what} {path}: {exc.strerror or exc}") from None
    if len(raw) > max_bytes:
        refuse_larger(path, max_bytes, what, advice)
    return raw


def refuse_larger(path, max_bytes: int, what: str, advice: str = ""):
    """Raise the refusal of a file found holding more than ``max_bytes`` while it was read (its size
    said less: a FIFO, a /proc file, a file that grows), worded as ``check_file_size``'s."""
    limit = _amount(max_bytes)
    raise ShapeMoveError(f"{path}: the {what} file is more than {limit} (it grew while being read, or is not a "
                         f"regular file); {what} files larger than {limit} are refused"
                         + (f" ({advice})" if advice else ""))


def read_text(path, what: str, max_bytes: int | None = None) -> str:
    """The text of a motion file: size bounded (``read_bounded``), binary files refused."""
    path = Path(path)
    raw = read_bounded(path, max_bytes or MAX_TEXT_BYTES, what, "split the clip")
    if b"\0" in raw[:4096]:
        raise ShapeMoveError(f"{path}: binary data, not an {what} text file")
    return raw.decode("utf-8", errors="replace")


def read_json(path, what: str, max_bytes: int = 1 << 20, advice: str = ""):
    """A user's JSON file (a preset, a config): 'WHAT not found: PATH'; at most ``max_bytes`` are
    read (``read_bounded``, the refusal ends with ``advice``); unreadable or invalid JSON is one
    sentence 'cannot read WHAT PATH: ...'."""
    path = Path(path)
    if not path.exists():
        raise ShapeMoveError(f"{what} not found: {path}")
    if path.is_dir():
        raise ShapeMoveError(f"cannot read {what} {path}: it is a folder")
    raw = read_bounded(path, max_bytes, what, advice)
    try:
        return json.loads(raw.decode("utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ShapeMoveError(f"cannot read {what} {path}: not valid JSON ({exc})") from None
    except RecursionError:
        raise ShapeMoveError(f"cannot read {what} {path}: not valid JSON (nested too deeply)") from None


def check_joint_frames(frames, joints, source, what: str = "clip") -> None:
    """Refuse a clip whose frames x joints would not fit the bounds above."""
    if frames * joints > MAX_JOINT_FRAMES:
        raise ShapeMoveError(f"{source}: the {what} has {int(frames):,} frames x {int(joints):,} joints, more than "
                             f"{MAX_JOINT_FRAMES:,} joint-frames (about {MAX_SECONDS / 60:.0f} min of a full body); "
                             "split it into shorter clips")


def parse_floats(text: str, count: int, source, what: str) -> np.ndarray:
    """The first ``count`` whitespace-separated numbers of ``text`` (fewer if the text ends first),
    parsed chunk by chunk so memory stays ~8 bytes per number (``str.split`` of the whole text
    would need ~60). Raises ShapeMoveError naming ``what`` on a token that is not a number."""
    out = np.empty(count, dtype=np.float64)
    n, pos, size = 0, 0, len(text)
    while n < count and pos < size:
        end = min(size, pos + _CHUNK)
        if end < size:  # cut at whitespace so no number is split
            cut = max(text.rfind(" ", pos, end), text.rfind("\n", pos, end), text.rfind("\t", pos, end))
            end = cut + 1 if cut > pos else end
        toks = text[pos:end].split()
        pos = end
        if not toks:
            continue
        toks = toks[: count - n]
        try:
            vals = np.array(toks, dtype=np.float64)
        except ValueError:
            bad = next(t for t in toks if not is_number(t))
            raise ShapeMoveError(f"{source}: {what} contains something that is not a number: {bad[:40]!r}") from None
        out[n: n + len(vals)] = vals
        n += len(vals)
    return out[:n]


def is_number(t: str) -> bool:
    """Whether the token ``t`` reads as a float (the readers name the first one that does not)."""
    try:
        float(t)
        return True
    except ValueError:
        return False
