"""``manifest.jsonl``: one JSON line per item of a batch, appended by one writer as items finish
(flushed and fsynced line by line, so a ``kill -9`` loses at most the items in flight).

A line (``"format": "shapemove-batch/1"``):
  item, line, of         the item's index in the prompts file, its line number, the file's item count
  kind                   "generate" or "render"
  key                    SHA-256 of what the outputs are a function of: kind, options, settings, model
  input                  the line as read ({"prompt": text} for a .txt line)
  options                resolved: prompt or sequence, shape_text, betas, seconds, seed, animation options
  settings               the batch's: sampling (temperature, top_k, candidates, guidance, retrieval ...),
                         body model, library, and for render frames / resolution / video
  model                  {"name", "manifest_sha256"}: the weights' manifest (model_identity.py)
  status                 "done" or "failed"; error: the reason of a failed item (else null)
  source                 where the motion came from: "generated", "retrieved" (a memory clip's tokens
                         kept) or "captured" (a library take played as captured), with notes and warnings
  result                 the motion's facts: frames, seconds, betas, shape source, IK error
  outputs                [{"file", "bytes", "sha256"}] relative to the manifest's folder
  timing                 {"seconds", "cpu_seconds" (the worker process's), "started" (UTC), "worker"
                         (host:pid)}: the only fields that differ
                         between two runs of the same line
A ``--shard I/N`` run writes ``manifest-I-of-N.jsonl`` so shards can share one folder.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from ..atomic import atomic_write_text, ensure_parent
from ..errors import ShapeMoveError
from .outputs import outputs_match
from .shard import Shard

FORMAT = "shapemove-batch/1"
RUN_FIELDS = ("timing",)   # what may differ between two runs of the same item


def manifest_name(shard: Shard) -> str:
    return "manifest.jsonl" if shard.count == 1 else f"manifest-{shard.index}-of-{shard.count}.jsonl"


def canonical(obj) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=False)


def item_key(kind: str, options: dict, settings: dict, model: dict) -> str:
    """What an item's files are a pure function of, hashed: a changed option, setting or model
    makes the item a different one (redone on resume, refused by merge)."""
    return hashlib.sha256(canonical([FORMAT, kind, options, settings, model]).encode()).hexdigest()


def comparable(record: dict) -> dict:
    """The record without the fields of one particular run (timing)."""
    return {k: v for k, v in record.items() if k not in RUN_FIELDS}


def read_manifest(path) -> tuple[list[dict], int]:
    """(records, lines skipped): a line that does not parse (the torn last line of a killed run)
    or is not a batch record is skipped and counted."""
    path = Path(path)
    if not path.is_file():
        return [], 0
    records, skipped = [], 0
    with open(path, encoding="utf-8", errors="replace") as fh:
        for ln in fh:
            try:
                rec = json.loads(ln)
            except (json.JSONDecodeError, RecursionError):
                skipped += bool(ln.strip())
                continue
            if isinstance(rec, dict) and rec.get("format") == FORMAT and isinstance(rec.get("item"), int):
                records.append(rec)
            else:
                skipped += 1
    return records, skipped


def finished_items(path, keys: dict) -> dict:
    """{item: record} of the items a manifest says are done, for the same key (``keys``: item ->
    key), whose files in the manifest's folder still match. When the manifest holds anything else
    (failed or stale items, a torn line, repeats) it is rewritten atomically with just these, so
    the items run again appear once."""
    path = Path(path)
    records, skipped = read_manifest(path)
    done: dict = {}
    for rec in records:   # the last line of an item wins
        if rec.get("status") == "done" and keys.get(rec["item"]) == rec.get("key") \
                and outputs_match(path.parent, rec.get("outputs") or []):
            done[rec["item"]] = rec
        else:
            done.pop(rec["item"], None)
    if skipped or len(done) != len(records):
        atomic_write_text(path, "".join(canonical(done[i]) + "\n" for i in sorted(done)))
    return done


class ManifestWriter:
    """Appends records, one line each, flushed and fsynced before ``append`` returns."""

    def __init__(self, path):
        self.path = ensure_parent(Path(path))
        try:
            self._fh = open(self.path, "a", encoding="utf-8")
        except OSError as exc:
            raise ShapeMoveError(f"cannot write the manifest {self.path}: {exc.strerror}") from None

    def append(self, record: dict) -> None:
        self._fh.write(canonical(record) + "\n")
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self) -> None:
        self._fh.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
