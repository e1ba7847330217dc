"""Join the manifests of a batch's shards (or of runs on several machines) into one folder: every
item once, its files copied beside the merged ``manifest.jsonl`` (checked against their SHA-256).
Refused: an item two manifests disagree on (another key, i.e. other options, settings or model,
or other files), items of different models, a listed file that is missing or does not match."""
from __future__ import annotations

import shutil
from dataclasses import dataclass, field
from pathlib import Path

from ..atomic import atomic_path, atomic_write_text
from ..errors import ShapeMoveError
from .manifest import canonical, comparable, read_manifest
from .outputs import outputs_match

MERGED = "manifest.jsonl"


@dataclass
class Merged:
    manifest: Path
    items: int = 0
    failed: int = 0
    copied: int = 0
    of: int | None = None
    missing: list = field(default_factory=list)   # items of the prompts file no manifest has


def _agree(a: dict, b: dict, where_a: Path, where_b: Path) -> dict:
    """The record to keep of two for one item."""
    if a.get("key") != b.get("key"):
        raise ShapeMoveError(f"item {a['item']} differs between {where_a} and {where_b} (other options, settings or "
                             "model): these manifests are not of one batch; refused")
    if a["status"] == "done" and b["status"] == "done":
        if [(e["file"], e["sha256"]) for e in a["outputs"]] != [(e["file"], e["sha256"]) for e in b["outputs"]]:
            raise ShapeMoveError(f"item {a['item']} has other files in {where_a} than in {where_b} (same line, same "
                                 "model, different bytes); refused")
        if comparable(a) != comparable(b):
            raise ShapeMoveError(f"item {a['item']} is recorded differently in {where_a} and {where_b}; refused")
        return a
    return a if a["status"] == "done" else b


def merge_manifests(manifests, out) -> Merged:
    out = Path(out)
    kept: dict = {}    # item -> (record, folder it lies in)
    models = {}
    counts = set()
    for m in map(Path, manifests):
        if not m.is_file():
            raise ShapeMoveError(f"manifest not found: {m}")
        records, _ = read_manifest(m)   # empty: a shard with no items (more shards than items)
        latest = {rec["item"]: rec for rec in records}   # within one manifest the last line of an item wins
        for item, rec in latest.items():
            models.setdefault(canonical(rec.get("model")), m)
            counts.add(rec.get("of"))
            if rec["status"] == "done" and not outputs_match(m.parent, rec["outputs"]):
                raise ShapeMoveError(f"{m}: the files of item {item} are missing or changed; run that shard "
                                     "again (it redoes them) and merge after")
            if item in kept:
                old, where = kept[item]
                choice = _agree(old, rec, where, m.parent)
                kept[item] = (choice, where if choice is old else m.parent)
            else:
                kept[item] = (rec, m.parent)
    if not kept:
        raise ShapeMoveError(f"{', '.join(map(str, manifests))}: no batch items in {'it' if len(manifests) == 1 else 'them'}")
    if len(models) > 1:
        a, b = list(models.values())[:2]
        raise ShapeMoveError(f"{a} and {b} were made with different models; refused")
    result = Merged(out / MERGED, items=len(kept))
    for item, (rec, folder) in sorted(kept.items()):
        result.failed += rec["status"] != "done"
        for e in rec["outputs"]:
            src, dst = folder / e["file"], out / e["file"]
            if src.resolve() == dst.resolve() or outputs_match(out, [e]):
                continue
            with atomic_path(dst) as tmp:
                shutil.copyfile(src, tmp)
            result.copied += 1
    if len(counts) == 1 and None not in counts:
        result.of = counts.pop()
        result.missing = [i for i in range(result.of) if i not in kept]
    atomic_write_text(result.manifest, "".join(canonical(kept[i][0]) + "\n" for i in sorted(kept)))
    return result
