"""Atomic file writes: write ``name.<pid>.tmp`` in the destination folder, then ``os.replace``.

A failed write (read-only folder, a parent that is a file, disk full, an exception in the caller)
removes the temporary file and raises ``ShapeMoveError`` naming the path and the reason, so
nothing half-written and no ``*.tmp`` is left behind, and the old file (if any) is untouched.

    with atomic_path(out) as tmp:          # any writer that takes a path
        torch.save(obj, tmp)
    atomic_write_bytes(path, data); atomic_write_text(path, text); atomic_write_json(path, obj)
    atomic_write_json(path, metrics, nan_to_null=True)   # NaN/inf -> null: valid JSON
    atomic_save_npy(path, array)           # np.save without pickles
"""
from __future__ import annotations

import contextlib
import errno
import json
import math
import os
from pathlib import Path

from .errors import ShapeMoveError

_REASONS = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is exceeded",
            errno.EROFS: "the file system is read-only", errno.EACCES: "permission denied",
            errno.EPERM: "permission denied", errno.ENOTDIR: "a parent of it is a file, not a folder",
            errno.EISDIR: "it is a folder", errno.ENAMETOOLONG: "the name is too long",
            errno.EEXIST: "a file is in the way", errno.EFBIG: "the file grew past the allowed size (disk full or a file-size limit)"}


def os_error_sentence(exc: OSError, path, verb: str = "write") -> str:
    """'cannot write PATH: the disk is full' from an OSError."""
    reason = _REASONS.get(exc.errno) or exc.strerror or type(exc).__name__
    return f"cannot {verb} {path}: {reason}"


def ensure_parent(path) -> Path:
    """Create the folder of ``path``; a sentence (not a traceback) when that is impossible."""
    path = Path(path)
    parent = path.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise ShapeMoveError(f"cannot write {path}: {parent} (or one of its parents) is a file, not a folder") from None
    except OSError as exc:
        raise ShapeMoveError(os_error_sentence(exc, path)) from None
    if not parent.is_dir():
        raise ShapeMoveError(f"cannot write {path}: {parent} is not a folder")
    if path.is_dir():
        raise ShapeMoveError(f"cannot write {path}: it is a folder")
    return path


def _remove(tmp: Path) -> None:
    with contextlib.suppress(OSError):
        tmp.unlink()


@contextlib.contextmanager
def atomic_path(path, suffix: str = ""):
    """Yield a temporary path beside ``path`` (ending in ``.tmp`` + ``suffix``, e.g. '.npz' for
    writers that insist on an extension); on success it replaces ``path``, on any failure it is
    removed. OSErrors become ShapeMoveError sentences."""
    path = ensure_parent(path)
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp{suffix}")
    try:
        yield tmp
        if not tmp.exists():
            raise ShapeMoveError(f"cannot write {path}: nothing was written")
        os.replace(tmp, path)
    except OSError as exc:
        _remove(tmp)
        raise ShapeMoveError(os_error_sentence(exc, path)) from None
    except BaseException:
        _remove(tmp)
        raise


def atomic_write_bytes(path, data: bytes) -> Path:
    path = Path(path)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    return path


def atomic_write_text(path, text: str, encoding: str = "utf-8") -> Path:
    return atomic_write_bytes(path, text.encode(encoding))


def json_safe(obj):
    """``obj`` with every non-finite float (NaN, inf) inside dicts, lists and tuples made None,
    so the JSON is valid (``json.dumps`` would write NaN)."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    return None if isinstance(obj, float) and not math.isfinite(obj) else obj


def atomic_write_json(path, obj, indent: int | None = 2, nan_to_null: bool = False, **kwargs) -> Path:
    """``obj`` as JSON (+ newline); ``nan_to_null``: non-finite floats written as null (``json_safe``)."""
    return atomic_write_text(path, json.dumps(json_safe(obj) if nan_to_null else obj, indent=indent, **kwargs) + "\n")


def atomic_save_npy(path, array) -> Path:
    """``np.save`` (allow_pickle=False: object arrays are refused) done atomically."""
    import numpy as np

    path = Path(path)
    with atomic_path(path, suffix=".npy") as tmp:
        with open(tmp, "wb") as fh:
            np.save(fh, np.asarray(array), allow_pickle=False)
    return path
