"""A built dataset's per-clip meta, read one way everywhere: ``meta.jsonl`` (one JSON object per clip,
written when ``data build`` finishes) and, for a dataset without it, ``meta/ID.json`` (one per clip,
written as each clip is built).

    for m in iter_meta(data): ...      # every clip's meta: meta.jsonl, else meta/*.json
    metas = read_meta(data, ids)       # {id: meta} of those clips, a missing one from meta/ID.json ({} if none)
    clip_meta(data, cid)               # one clip's meta/ID.json ({} when it has none)
    is_real(meta)                      # a captured clip as performed, not a copy made from one

Sizes are bounded before and while reading (``core/io/limits``): meta.jsonl at ``MAX_META_BYTES``,
read line by line (a line that is not a JSON object is refused, naming the line); one meta/ID.json
at ``MAX_CLIP_META_BYTES``: a clip whose meta/ID.json is too large or not valid JSON is treated as a
clip without meta, with a one-line note on stderr (once per file), so one damaged file does not
stop a training run.
"""
from __future__ import annotations

import json
import sys
from collections.abc import Iterator
from pathlib import Path

from ..errors import ShapeMoveError
from ..io.limits import check_file_size, read_json, refuse_larger

MAX_META_BYTES = 256 << 20       # meta.jsonl (~1 KB a clip: 250,000 clips)
MAX_CLIP_META_BYTES = 1 << 20    # one clip's meta/ID.json
JSONL, FOLDER = "meta.jsonl", "meta"
ADVICE = "rebuild the dataset with `python -m shapemove data build`"
_noted: set = set()


def clip_meta(data, cid: str) -> dict:
    """The meta of clip ``cid`` from ``meta/{cid}.json``; {} when it has none, or (with a note) when
    it is too large or not a JSON object."""
    f = Path(data) / FOLDER / f"{cid}.json"
    if not f.is_file():
        return {}
    try:
        meta = read_json(f, "clip meta", MAX_CLIP_META_BYTES)
    except ShapeMoveError as exc:
        _note(f, str(exc))
        return {}
    if not isinstance(meta, dict):
        _note(f, f"{f}: not a JSON object")
        return {}
    return meta


def _jsonl(data: Path) -> Iterator[dict]:
    """The objects of ``data/meta.jsonl``, line by line, never more than MAX_META_BYTES read."""
    jl = data / JSONL
    what = JSONL
    check_file_size(jl, MAX_META_BYTES, what, ADVICE)
    left, n = MAX_META_BYTES, 0
    try:
        with open(jl, "rb") as fh:
            while line := fh.readline(left + 1):
                n += 1
                left -= len(line)
                if left < 0:  # grew while read, or not a regular file
                    refuse_larger(jl, MAX_META_BYTES, what, ADVICE)
                if not line.strip():
                    continue
                try:
                    m = json.loads(line)
                except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as exc:
                    raise ShapeMoveError(f"{jl}: line {n} is not valid JSON ({exc}); {ADVICE}") from None
                if not isinstance(m, dict):
                    raise ShapeMoveError(f"{jl}: line {n} is not a JSON object (one clip's meta); {ADVICE}")
                yield m
    except OSError as exc:
        raise ShapeMoveError(f"cannot read {jl}: {exc.strerror or exc}") from None


def iter_meta(data) -> Iterator[dict]:
    """Every clip's meta of the built dataset ``data``: the lines of ``meta.jsonl`` when it exists,
    else each ``meta/*.json`` (sorted by name); neither is 'not a built dataset'."""
    data = Path(data)
    if (data / JSONL).is_file():
        yield from _jsonl(data)
    elif (data / FOLDER).is_dir():
        for p in sorted((data / FOLDER).glob("*.json")):
            meta = clip_meta(data, p.stem)
            if meta:
                yield meta
    else:
        raise ShapeMoveError(f"{data}: not a built dataset (no {JSONL} or {FOLDER}/ folder)")


def read_meta(data, ids) -> dict[str, dict]:
    """{clip id: its meta} for each of ``ids``: from ``meta.jsonl`` (the last line with that id), a
    clip it does not list (or every clip, without meta.jsonl) from ``meta/ID.json``; {} for a clip
    with neither."""
    data = Path(data)
    want, out = set(ids), {}
    if (data / JSONL).is_file():
        for m in _jsonl(data):
            if isinstance(m.get("id"), str) and m["id"] in want:
                out[m["id"]] = m
    for cid in ids:
        if cid not in out:
            out[cid] = clip_meta(data, cid)
    return out


def _note(path: Path, text: str) -> None:
    key = str(path)
    if key not in _noted:
        _noted.add(key)
        print(f"note: {text}; the clip is used without its meta (actions, labels)", file=sys.stderr)


def is_real(meta: dict) -> bool:
    """A captured clip, not a shape-augmented, mirrored or composed copy."""
    return not any(meta.get(k) for k in ("augmented_from", "mirror_of", "composed_from")) and \
        not str(meta.get("id", "")).endswith("_aug")
