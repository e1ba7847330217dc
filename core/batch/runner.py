"""A batch from its items to its manifest: the items the manifest already has done (files still
matching) are skipped, the rest go to the engine, and each finished item's record is appended to
the manifest by this process alone, with the progress line updated."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from .engines import InProcess
from .manifest import ManifestWriter, finished_items, item_key, manifest_name
from .progress import BatchProgress
from .shard import ALL, Shard


@dataclass
class BatchResult:
    manifest: Path
    total: int                      # this shard's items
    skipped: int                    # done before this run
    done: int = 0
    failed: list = field(default_factory=list)   # (item, label, error)


def item_specs(kind: str, items, count: int, settings: dict, model: dict, where: dict) -> list[dict]:
    """What a worker gets per item: the manifest's identity fields (``item_run.SPEC_FIELDS``), the
    files' stem, and ``where`` (this machine's model, body model and library paths, which the
    manifest names by folder only, so shards on other machines agree)."""
    return [{"item": it.index, "line": it.line, "of": count, "kind": kind,
             "key": item_key(kind, it.options, settings, model), "input": it.input, "options": it.options,
             "settings": settings, "model": model, "stem": it.stem, "where": where} for it in items]


def remove_leftovers(folder: Path, stems) -> int:
    """Remove the temporary files (``NAME.PID.tmp``, core/atomic.py) a killed run left of the
    items about to run (and of its manifest, ``stems`` holding the manifest's name); a finished
    file never has that name, so none is mistaken for one."""
    stems, removed = set(stems), 0
    if folder.is_dir():
        for p in folder.iterdir():
            if ".tmp" in p.name and p.name.split(".")[0] in stems and p.is_file():
                p.unlink(missing_ok=True)
                removed += 1
    return removed


def run_batch(kind: str, task, items, count: int, settings: dict, model: dict, where: dict, folder, engine=None,
              shard: Shard = ALL, progress_stream=None, interval: float = 10.0) -> BatchResult:
    """Run ``task`` on the ``items`` not yet done into ``folder``; ``count``: the file's items."""
    folder = Path(folder)
    engine = engine or InProcess()
    specs = item_specs(kind, items, count, settings, model, where)
    manifest = folder / manifest_name(shard)
    done_before = finished_items(manifest, {s["item"]: s["key"] for s in specs})
    todo = [s for s in specs if s["item"] not in done_before]
    remove_leftovers(folder, [s["stem"] for s in todo] + [manifest.name.split(".")[0]])
    result = BatchResult(manifest, len(specs), len(specs) - len(todo))
    progress = BatchProgress(len(specs), result.skipped, label=kind, stream=progress_stream, interval=interval)
    labels = {it.index: it.label for it in items}
    if result.skipped:
        progress.write(f"{kind}: {result.skipped} of {len(specs)} items already done ({manifest.name}), "
                       f"{len(todo)} to run")
    try:
        with ManifestWriter(manifest) as writer:
            for record in engine.run(task, todo, folder):
                writer.append(record)
                ok = record["status"] == "done"
                for note in (record.get("source") or {}).get("notes") or []:   # a library take played as captured
                    progress.write(f"item {record['item']}: {note}")
                if ok:
                    result.done += 1
                else:
                    result.failed.append((record["item"], labels[record["item"]], record["error"]))
                    progress.write(f"item {record['item']} ({labels[record['item']][:40]!r}) failed: {record['error']}")
                progress.update(ok)
    finally:
        progress.close()
    return result
