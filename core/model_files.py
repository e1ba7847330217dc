"""Integrity of model files: a ``manifest.json`` beside them lists each file's sha256 and size, and
loading checks it, so a corrupted, truncated or swapped file is refused with a sentence instead of
silently producing different motions.

    write_manifest(folder)            # after saving/exporting a model folder: lists every file below
    add_to_manifest(folder, [path])   # after (re)writing one file in a run folder (checkpoints)
    verify_manifest(folder, required=("tokenizer.json",))   # before loading a folder
    verify_file(path)                 # before loading one file

A manifest covers the files below its folder; loading looks for the nearest manifest that lists the
file in the file's folder and up to two levels above (``weights/default/manifest.json`` covers
``t5/model.safetensors`` and ``tma/tma.pt``). A folder no manifest covers is loaded with a one-line
note on stderr (older exports); a file a manifest lists must match it.

manifest.json = {"format": "shapemove-manifest/1", "files": {"t5/model.safetensors": {"sha256": ..., "bytes": N}}}
"""
from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

from .atomic import atomic_write_json
from .errors import ShapeMoveError
from .io.limits import read_bounded

MANIFEST = "manifest.json"
FORMAT = "shapemove-manifest/1"
MAX_MANIFEST_BYTES = 4 << 20
SKIP_SUFFIXES = (".tmp", ".partial", ".lock")
_hash_cache: dict = {}  # (path, size, mtime_ns) -> sha256: a file is hashed once per process
_noted: set = set()


def sha256_file(path: Path) -> str:
    path = Path(path)
    st = path.stat()
    key = (str(path.resolve()), st.st_size, st.st_mtime_ns)
    if key not in _hash_cache:
        h = hashlib.sha256()
        with open(path, "rb") as fh:
            while chunk := fh.read(1 << 20):
                h.update(chunk)
        _hash_cache[key] = h.hexdigest()
    return _hash_cache[key]


def _entry(path: Path) -> dict:
    return {"sha256": sha256_file(path), "bytes": path.stat().st_size}


def _listed_files(folder: Path) -> list[Path]:
    def skipped(p: Path) -> bool:
        return any(part.endswith(SKIP_SUFFIXES) for part in p.relative_to(folder).parts)

    return sorted(p for p in folder.rglob("*")
                  if p.is_file() and not p.is_symlink() and p.name != MANIFEST and not skipped(p))


def write_manifest(folder) -> Path:
    """List every file below ``folder`` (sha256 + size) in ``folder/manifest.json``; manifests in
    subfolders are removed (this one covers them). Returns the manifest path."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ShapeMoveError(f"cannot write a manifest: {folder} is not a folder")
    for nested in folder.rglob(MANIFEST):
        if nested.parent != folder:
            nested.unlink()
    files = {p.relative_to(folder).as_posix(): _entry(p) for p in _listed_files(folder)}
    return atomic_write_json(folder / MANIFEST, {"format": FORMAT, "files": files}, sort_keys=True)


def _read(manifest: Path) -> dict:
    raw = read_bounded(manifest, MAX_MANIFEST_BYTES, "model manifest", "re-export or re-train the model")
    try:
        data = json.loads(raw.decode("utf-8"))
        if not isinstance(data, dict) or data.get("format") != FORMAT or not isinstance(data.get("files"), dict):
            raise ValueError(f"not a {FORMAT} manifest")
        for name, e in data["files"].items():
            if not (isinstance(e, dict) and isinstance(e.get("sha256"), str) and isinstance(e.get("bytes"), int)):
                raise ValueError(f"bad entry for {name!r}")
    except (OSError, ValueError, UnicodeDecodeError, RecursionError) as exc:
        raise ShapeMoveError(f"{manifest} is damaged ({exc}): the model folder cannot be checked; re-export or "
                             "re-train it") from None
    return data


def add_to_manifest(folder, paths) -> Path:
    """Add or refresh the entries of ``paths`` (files below ``folder``) in ``folder/manifest.json``."""
    folder = Path(folder)
    manifest = folder / MANIFEST
    data = _read(manifest) if manifest.is_file() else {"format": FORMAT, "files": {}}
    for p in paths:
        p = Path(p)
        data["files"][p.resolve().relative_to(folder.resolve()).as_posix()] = _entry(p)
    return atomic_write_json(manifest, data, sort_keys=True)


def _covering(path: Path):
    """(manifest folder, its entries under ``path``) of the nearest manifest listing ``path``."""
    path = path.resolve()
    start = path if path.is_dir() else path.parent
    for folder in (start, start.parent, start.parent.parent):
        manifest = folder / MANIFEST
        if not manifest.is_file():
            continue
        rel = path.relative_to(folder).as_posix()
        files = _read(manifest)["files"]
        if path.is_dir():
            hits = {k: v for k, v in files.items() if rel == "." or k.startswith(rel + "/")}
        else:
            hits = {k: v for k, v in files.items() if k == rel}
        if hits:
            return folder, hits
    return None, {}


def _check(folder: Path, entries: dict, what: Path) -> None:
    for rel, e in entries.items():
        p = folder / rel
        if ".." in Path(rel).parts or Path(rel).is_absolute():
            raise ShapeMoveError(f"{folder / MANIFEST} lists a path outside its folder ({rel!r}); refused")
        if not p.is_file():
            raise ShapeMoveError(f"model file {p} is missing (listed in {folder / MANIFEST}); re-export or re-train "
                                 "the model")
        size = p.stat().st_size
        if size != e["bytes"]:
            raise ShapeMoveError(f"model file {p} is damaged or was replaced: {size} bytes, the manifest says "
                                 f"{e['bytes']} (truncated or swapped file); re-export or re-train the model")
        if sha256_file(p) != e["sha256"]:
            raise ShapeMoveError(f"model file {p} is damaged or was replaced: its sha256 differs from "
                                 f"{folder / MANIFEST}; re-export or re-train the model")


def listed_in_manifest(folder, rel: str) -> bool:
    """Whether ``folder/manifest.json`` lists the file ``rel`` (so the folder was exported with it
    and its absence is damage, not an older or smaller model)."""
    manifest = Path(folder) / MANIFEST
    return manifest.is_file() and rel in _read(manifest)["files"]


def _note(path: Path) -> None:
    key = str(path.resolve())
    if key not in _noted:
        _noted.add(key)
        print(f"note: {path} is not listed in any {MANIFEST}: its integrity is not checked "
              "(re-export the model to add one)", file=sys.stderr)


def _verify_covered(target: Path) -> bool:
    """Check ``target`` (a file or a folder) against the manifest covering it: False with a note
    when none does."""
    root, entries = _covering(target)
    if not entries:
        _note(target)
        return False
    _check(root, entries, target)
    return True


def verify_file(path) -> bool:
    """Check one model file against the manifest that lists it. True when checked, False (with a
    note) when no manifest lists it; ShapeMoveError when it is missing or differs."""
    path = Path(path)
    if not path.is_file():
        raise ShapeMoveError(f"model file {path} not found")
    return _verify_covered(path)


def verify_manifest(folder, required=()) -> bool:
    """Check every file a manifest lists below ``folder`` and that each of ``required`` (names
    relative to ``folder``) exists. True when a manifest covered it, False (with a note) if none."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ShapeMoveError(f"model folder {folder} not found")
    missing = [r for r in required if not (folder / r).is_file()]
    if missing:
        raise ShapeMoveError(f"model folder {folder} is incomplete: {', '.join(missing)} missing; re-export or "
                             "re-train the model (a model without its files would silently produce garbage)")
    return _verify_covered(folder)


class damaged_model_errors:
    """``with damaged_model_errors(folder): load...``: an error while reading model files (garbage
    JSON, a truncated safetensors, a tokenizer that does not parse, mismatched tensors) becomes
    ShapeMoveError naming the folder, instead of a traceback."""

    def __init__(self, folder):
        self.folder = Path(folder)

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if exc is None or isinstance(exc, ShapeMoveError) or not isinstance(exc, Exception):
            return False
        module = type(exc).__module__ or ""
        if isinstance(exc, (OSError, ValueError, RuntimeError, KeyError, TypeError, IndexError, AttributeError,
                            EOFError, RecursionError)) or type(exc) is Exception \
                or module.split(".")[0] in ("safetensors", "safetensors_rust", "tokenizers", "huggingface_hub",
                                            "transformers"):
            text = " ".join(str(exc).split())[:300]
            raise ShapeMoveError(f"model folder {self.folder} is damaged or incomplete ({type(exc).__name__}: {text}); "
                                 "re-export or re-train the model") from None
        return False
