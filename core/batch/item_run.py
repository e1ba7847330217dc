"""One item run where an engine put it (this process, a worker process, a Dask worker): the task
``task(spec, folder) -> {"files", "source", "result"}`` writes its files into ``folder``; this
times it (wall seconds, and the CPU seconds of the process that ran it: on a shared machine the
wall time includes waiting for a core), hashes the files and turns its failure into the item's
error, so one bad item never stops a batch. ``run_remote`` runs it in a scratch folder and
returns the files' bytes, for a worker that shares no disk with the writer."""
from __future__ import annotations

import os
import socket
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

from ..errors import ShapeMoveError
from .manifest import FORMAT
from .outputs import file_entry

SPEC_FIELDS = ("item", "line", "of", "kind", "key", "input", "options", "settings", "model")


def run_item(task, spec: dict, folder) -> dict:
    """The item's manifest record (``spec`` holds its identity: ``SPEC_FIELDS``)."""
    started = datetime.now(timezone.utc).isoformat(timespec="milliseconds").replace("+00:00", "Z")
    t0, c0 = time.perf_counter(), time.process_time()
    record = {"format": FORMAT, **{k: spec[k] for k in SPEC_FIELDS}}
    try:
        got = task(spec, Path(folder))
        record.update(status="done", error=None, source=got.get("source"), result=got.get("result"),
                      outputs=[file_entry(Path(folder), name) for name in got["files"]])
    except ShapeMoveError as exc:
        record.update(status="failed", error=str(exc), source=None, result=None, outputs=[])
    except Exception as exc:  # noqa: BLE001  (a bug in one item is that item's error; the batch goes on)
        record.update(status="failed", error=f"{type(exc).__name__}: {exc}", source=None, result=None, outputs=[])
    record["timing"] = {"seconds": round(time.perf_counter() - t0, 3),
                        "cpu_seconds": round(time.process_time() - c0, 3), "started": started,
                        "worker": f"{socket.gethostname()}:{os.getpid()}"}
    return record


def run_remote(task, spec: dict) -> tuple[dict, dict]:
    """(record, {file name: bytes}) of the item run in a scratch folder."""
    with tempfile.TemporaryDirectory(prefix="shapemove_item_") as tmp:
        record = run_item(task, spec, tmp)
        return record, {e["file"]: (Path(tmp) / e["file"]).read_bytes() for e in record["outputs"]}
