"""One loaded ``Generator`` per process, reused by every request for the same model folder, body
model and library: the worker's jobs and the commands it runs in-process (its ``cli`` op) load the
T5, SA-VAE and TMA once, not once per request.

A changed model or library file loads it again; one model set is kept at a time. Each hand-out
turns retrieval on (``Generator.set_retrieval``): a request that turns it off does so for itself.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import ShapeMoveError
from .model_bundle import resolve_model_dir

_LOADED: dict = {}


def loaded_generator(model=None, body=None, library=None):
    """The ``Generator`` for (model folder or None = the default, body spec or None = OpenBody,
    library folder or None: the user's captioned motions added to its memory,
    ``Generator.add_library``), loaded on first use (module doc)."""
    from ..search.motion_search import list_library
    from .generate import Generator

    d = resolve_model_dir(model or None)
    stamp = max((p.stat().st_mtime_ns for p in d.rglob("*") if p.is_file()), default=0)
    lib = None
    if library:
        folder = Path(library)
        if not folder.is_dir():
            raise ShapeMoveError(f"library folder not found: {folder}")
        files = [f for _, _, deps in list_library(folder) for f in deps if f.is_file()]
        lib = (str(folder.resolve()), len(files), max((f.stat().st_mtime_ns for f in files), default=0))
    key = (str(d.resolve()), str(body or "openbody"), stamp, lib)
    if key not in _LOADED:
        _LOADED.clear()  # one loaded model set at a time
        gen = Generator(d, body=body or None)
        if lib is not None:
            gen.add_library(lib[0])
        _LOADED[key] = gen
    gen = _LOADED[key]
    gen.set_retrieval(True)
    return gen
