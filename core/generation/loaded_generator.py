"""One loaded ``Generator`` per process, reused by every request for the same model folder, body
model and library: the worker's jobs, the commands it runs in-process (its ``cli`` op) and a
batch's worker processes (``core/batch/generate_item.py``) load the T5, SA-VAE and TMA once, not
once per request.

A changed model or library loads it again: the model folder is stamped by its ``manifest.json``
(which lists every weight file's SHA-256, and loading checks the files against it; a folder
without one by all its files), so a hand-out stats one file, not the whole folder. One model set
is kept at a time. Each hand-out turns retrieval and captured takes on (``Generator.set_retrieval``,
``set_captured``): a request that turns one off does so for itself.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import ShapeMoveError
from ..model_files import MANIFEST
from .model_bundle import resolve_model_dir

_LOADED: dict = {}


def _stamp(folder: Path) -> tuple:
    """What says the model folder changed: its manifest's size and time, else every file's time."""
    try:
        st = (folder / MANIFEST).stat()
        return MANIFEST, st.st_size, st.st_mtime_ns
    except OSError:
        return "files", max((p.stat().st_mtime_ns for p in folder.rglob("*") if p.is_file()), default=0)


def loaded_generator(model=None, body=None, library=None, on_load=None):
    """The ``Generator`` for (model folder or None = the default, body spec or None = OpenBody,
    library folder or None: the user's captioned motions added to its memory,
    ``Generator.add_library``), loaded on first use (module doc). ``on_load(gen, clips)`` is
    called when it is loaded (``clips``: the library's clips added, or None without a library)."""
    from ..search.motion_search import list_library
    from .generate import Generator

    d = resolve_model_dir(model or None)
    lib = None
    if library:
        folder = Path(library)
        if not folder.is_dir():
            raise ShapeMoveError(f"library folder not found: {folder}")
        files = [f for _, _, deps in list_library(folder) for f in deps if f.is_file()]
        lib = (str(folder.resolve()), len(files), max((f.stat().st_mtime_ns for f in files), default=0))
    key = (str(d.resolve()), str(body or "openbody"), _stamp(d), lib)
    if key not in _LOADED:
        _LOADED.clear()  # one loaded model set at a time
        gen = Generator(d, body=body or None)
        clips = gen.add_library(lib[0]) if lib is not None else None
        _LOADED[key] = gen
        if on_load is not None:
            on_load(gen, clips)
    gen = _LOADED[key]
    gen.set_retrieval(True)
    gen.set_captured(True)
    return gen
