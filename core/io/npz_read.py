"""Read arrays from an untrusted ``.npz`` without pickles and without trusting its headers: each
member's header (shape, dtype) is read first, object (pickled) arrays are refused, and the total
size is checked before any array is allocated -- a 1 KB file cannot ask for gigabytes."""
from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError

MAX_HEADER = 10_000


def read_npz(path, keys=None, max_bytes: int = 512 * 2**20, skip_objects=(), what: str = ".npz file") -> dict:
    """{key: array} for ``keys`` (all members when None) present in the file. ``skip_objects``:
    keys whose pickled value is silently skipped (optional metadata); any other pickled array is
    refused. Raises ShapeMoveError naming the file and the problem."""
    path = Path(path)
    try:
        with zipfile.ZipFile(path) as zf:
            members = {n[:-4]: n for n in zf.namelist() if n.endswith(".npy")}
            wanted = [k for k in (members if keys is None else keys) if k in members]
            shapes = {}
            for k in wanted:
                with zf.open(members[k]) as fh:
                    version = np.lib.format.read_magic(fh)
                    shape, _, dtype = np.lib.format._read_array_header(fh, version, max_header_size=MAX_HEADER)
                if dtype.hasobject:
                    if k in skip_objects:
                        continue
                    raise ShapeMoveError(f"{path}: {k} is a pickled Python object; pickles inside .npz files are "
                                         f"never loaded - save {k} as a plain (dense) array")
                shapes[k] = (shape, dtype)
            total = sum(float(np.prod(s, dtype=np.float64)) * max(d.itemsize, 8) for s, d in shapes.values())
            if total > max_bytes:
                raise ShapeMoveError(f"{path}: its arrays would take {total / 2**20:,.0f} MB, more than any {what} "
                                     f"({max_bytes // 2**20} MB); refused")
            out = {}
            for k in shapes:
                with zf.open(members[k]) as fh:
                    out[k] = np.lib.format.read_array(fh, allow_pickle=False, max_header_size=MAX_HEADER)
            return out
    except ShapeMoveError:
        raise
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zipfile.LargeZipFile) as exc:
        raise ShapeMoveError(f"{path}: not a readable {what} ({type(exc).__name__}: {str(exc)[:160]})") from None
