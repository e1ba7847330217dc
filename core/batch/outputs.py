"""An item's output files as the manifest lists them: name (relative to the batch folder), size
and SHA-256; and whether the files on disk still match."""
from __future__ import annotations

import hashlib
from pathlib import Path


def sha256_of(path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(1 << 20):
            h.update(chunk)
    return h.hexdigest()


def file_entry(folder: Path, name: str) -> dict:
    p = Path(folder) / name
    return {"file": name, "bytes": p.stat().st_size, "sha256": sha256_of(p)}


def outputs_match(folder: Path, entries: list) -> bool:
    """Every listed file exists in ``folder`` with its size and SHA-256."""
    for e in entries:
        p = Path(folder) / e["file"]
        try:
            if p.stat().st_size != e["bytes"] or sha256_of(p) != e["sha256"]:
                return False
        except OSError:
            return False
    return True
