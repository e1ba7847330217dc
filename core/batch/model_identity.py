"""Which model made a batch: the SHA-256 of its folder's ``manifest.json`` (core/model_files.py),
which lists every weight file's SHA-256, so two folders with the same weights have the same
identity wherever they lie. A folder without a manifest is identified by its files' hashes."""
from __future__ import annotations

import hashlib
from pathlib import Path

from ..model_files import MANIFEST, sha256_file


def model_identity(folder) -> dict:
    folder = Path(folder)
    manifest = folder / MANIFEST
    if manifest.is_file():
        return {"name": folder.name, "manifest_sha256": hashlib.sha256(manifest.read_bytes()).hexdigest()}
    h = hashlib.sha256()
    for p in sorted(q for q in folder.rglob("*") if q.is_file()):
        h.update(f"{p.relative_to(folder).as_posix()}\0{sha256_file(p)}\n".encode())
    return {"name": folder.name, "files_sha256": h.hexdigest()}
