"""The items of a batch: a prompts file read line by line, each line checked and its options
resolved (the line's own keys, else the command line's defaults), only the shard's items kept.

A ``.txt`` file holds one prompt per line (``#`` starts a comment). A ``.jsonl`` file holds one
object per line with "prompt" (or "sequence": [{"prompt", "seconds"}, ...], a timeline) and
optionally "shape_text", "betas", "seconds", "seed" and the animation options "loop", "in_place",
"path" ([[x, z], ...] metres, or a JSON file next to the prompts file), "speed", "stretch", and
for ``render`` "root_motion". A key the command does not know is refused (a typo would otherwise
be silently ignored). Item ``i`` (0-based, blank and comment lines not counted) has seed
``base_seed + i`` unless its line gives one, and writes ``{i:03d}_{slug}.*``.

The file is streamed: memory grows with the shard's items, not the file; a line longer than
``MAX_LINE`` characters is refused.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

from ..errors import ShapeMoveError
from .shard import ALL, Shard

MAX_LINE = 1 << 20
ANIMATION_KEYS = ("loop", "in_place", "path", "speed", "stretch")
LINE_KEYS = ("prompt", "sequence", "shape_text", "betas", "seconds", "seed", *ANIMATION_KEYS)
ROOT_MOTIONS = ("PELVIS", "OBJECT", "ROOT_BONE", "NONE")


@dataclass
class BatchItem:
    index: int      # position among the file's items (0-based): its seed and file names follow it
    line: int       # line number in the prompts file (1-based)
    input: dict     # the line as read ({"prompt": text} for a .txt line)
    options: dict   # resolved: prompt or sequence, shape_text, betas, seconds, seed, animation options

    @property
    def label(self) -> str:
        o = self.options
        return o.get("prompt") or " then ".join(str(s["prompt"]) for s in o.get("sequence") or [])

    @property
    def stem(self) -> str:
        return f"{self.index:03d}_{slug(self.label)}"


def slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")[:40] or "prompt"


def _number(v, key: str):
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ShapeMoveError(f'"{key}" must be a number, got {v!r}')
    return float(v)


def _text(v, key: str):
    if v is not None and not isinstance(v, str):
        raise ShapeMoveError(f'"{key}" must be text, got {v!r}')
    return v


def _betas(v):
    if v is None:
        return None
    if isinstance(v, list):
        if not all(isinstance(b, (int, float)) and not isinstance(b, bool) for b in v):
            raise ShapeMoveError(f'"betas" must be numbers, got {v!r}')
        v = ",".join(repr(float(b)) for b in v)
    if not isinstance(v, str):
        raise ShapeMoveError(f'"betas" must be a list of numbers or "b0,b1,...", got {v!r}')
    from ..generation.generate import parse_betas  # torch: only for lines that give betas

    return [float(b) for b in parse_betas(v)]


def _sequence(v):
    if not isinstance(v, list) or not v or not all(
            isinstance(s, dict) and isinstance(s.get("prompt"), str) and s["prompt"].strip()
            and _number(s.get("seconds"), "seconds") is not None for s in v):
        raise ShapeMoveError('a "sequence" is a list of {"prompt", "seconds"} objects')
    return [{"prompt": s["prompt"], "seconds": float(s["seconds"])} for s in v]


class _Paths:
    """Path files named by lines, read once each, relative to the prompts file."""

    def __init__(self, base: Path):
        self.base, self.cache = base, {}

    def points(self, v):
        if v is None:
            return None
        from ..generation.path_follow import read_path
        from ..generation.polyline import check_path

        if isinstance(v, str):
            if v not in self.cache:
                self.cache[v] = [[float(x), float(z)] for x, z in read_path(self.base / v)]
            return self.cache[v]
        return [[float(x), float(z)] for x, z in check_path(v)]


def _animation(anim: dict) -> dict:
    """The animation options checked (contradictions refused now, not on a worker); torch is
    imported only for a line that asks for one."""
    if not any(v not in (None, False) for v in anim.values()):
        return anim
    from ..generation.animate import animation_from

    a = animation_from(dict(anim))
    return {"loop": a.loop, "in_place": a.in_place, "path": anim["path"], "speed": a.speed, "stretch": a.stretch}


def resolve(obj: dict, index: int, defaults: dict, keys, paths: _Paths) -> dict:
    """One line's options: its own keys, else ``defaults``; checked (ShapeMoveError says what)."""
    if not set(obj) <= set(keys):
        unknown = sorted(set(obj) - set(keys))
        raise ShapeMoveError(f"unknown key{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))} "
                             f"(known: {', '.join(keys)})")
    merged = {**defaults, **obj}
    out: dict = {}
    if "sequence" in obj:
        if "prompt" in obj:
            raise ShapeMoveError('give "prompt" or "sequence", not both')
        out["sequence"] = _sequence(obj["sequence"])
    else:
        prompt = obj.get("prompt")
        if not isinstance(prompt, str) or not prompt.strip():
            raise ShapeMoveError('each line needs a "prompt" (text) or a "sequence" of {"prompt", "seconds"}')
        out["prompt"] = prompt
    out["shape_text"] = _text(merged.get("shape_text"), "shape_text")
    out["betas"] = _betas(merged.get("betas"))
    out["seconds"] = _number(merged.get("seconds"), "seconds")
    if out["seconds"] is not None and out["seconds"] <= 0:
        raise ShapeMoveError(f'"seconds" must be positive, got {out["seconds"]:g}')
    seed = obj["seed"] if "seed" in obj else int(defaults.get("seed") or 0) + index
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise ShapeMoveError(f'"seed" must be a whole number >= 0, got {seed!r}')
    out["seed"] = seed
    for key in ("loop", "in_place"):
        if merged.get(key) is not None and not isinstance(merged.get(key), bool):
            raise ShapeMoveError(f'"{key}" must be true or false, got {merged.get(key)!r}')
    out.update(_animation({"loop": bool(merged.get("loop")), "in_place": bool(merged.get("in_place")),
                           "path": paths.points(merged.get("path")), "speed": _number(merged.get("speed"), "speed"),
                           "stretch": _number(merged.get("stretch"), "stretch")}))
    if "root_motion" in keys:
        rm = str(merged.get("root_motion") or "PELVIS").upper()
        if rm not in ROOT_MOTIONS:
            raise ShapeMoveError(f'"root_motion" must be one of {", ".join(ROOT_MOTIONS)}, got {rm!r}')
        out["root_motion"] = rm
    return out


def _objects(path: Path):
    """(line number, object) of each item line, streamed."""
    jsonl = path.suffix.lower() == ".jsonl"
    with open(path, encoding="utf-8", errors="replace", newline=None) as fh:
        for number, ln in enumerate(iter(lambda: fh.readline(MAX_LINE + 1), ""), 1):
            if len(ln) > MAX_LINE:
                raise ShapeMoveError(f"{path}:{number}: the line is longer than {MAX_LINE:,} characters")
            text = ln.strip()
            if not text or (not jsonl and text.startswith("#")):
                continue
            if not jsonl:
                yield number, {"prompt": text}
                continue
            try:
                obj = json.loads(text)
            except (json.JSONDecodeError, RecursionError) as exc:
                raise ShapeMoveError(f"{path}:{number}: not valid JSON ({getattr(exc, 'msg', exc)})") from None
            if not isinstance(obj, dict):
                raise ShapeMoveError(f"{path}:{number}: each line needs an object with a \"prompt\" "
                                     "(or a \"sequence\" of {\"prompt\", \"seconds\"})")
            yield number, obj


def read_items(path, shard: Shard = ALL, defaults: dict | None = None, keys=LINE_KEYS) -> tuple[list[BatchItem], int]:
    """(this shard's items, the file's item count). Every line is checked, so each shard of a
    file refuses the same bad line."""
    path = Path(path)
    if not path.is_file():
        raise ShapeMoveError(f"prompts file not found: {path}")
    defaults = defaults or {}
    paths = _Paths(path.parent)
    items, count = [], 0
    for number, obj in _objects(path):
        try:
            options = resolve(obj, count, defaults, keys, paths)
        except ShapeMoveError as exc:
            raise ShapeMoveError(f"{path}:{number}: {exc}") from None
        if shard.holds(count):
            items.append(BatchItem(count, number, obj, options))
        count += 1
    if not count:
        raise ShapeMoveError(f"{path} holds no prompts")
    return items, count
