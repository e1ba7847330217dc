"""Where trained models live and how a set of them is loaded together.

A model folder holds ``savae.pt`` (SA-VAE), ``t5/`` (ShapeMove T5: save_pretrained + tokenizer +
[BETA] head) and optionally ``tma/tma.pt`` (text-motion alignment). The embedded default is
``weights/default`` in the package; a user's own models are any folder of the same layout
(inside Blender: under ``bpy.utils.extension_path_user``).
"""
from __future__ import annotations

import sys
from pathlib import Path

from ..errors import ShapeMoveError
from ..io.limits import read_json
from ..model_files import listed_in_manifest

PACKAGE_ROOT = Path(__file__).resolve().parents[2]
DEFAULT_MODEL_DIR = PACKAGE_ROOT / "weights" / "default"


def resolve_model_dir(path=None) -> Path:
    d = Path(path) if path else DEFAULT_MODEL_DIR
    if not d.is_dir():
        if path is None:
            raise ShapeMoveError(f"the default model is missing ({d}); rebuild it with `make train-default` "
                                 "or pass --model DIR")
        raise ShapeMoveError(f"model folder not found: {d}")
    return d


def model_files(d: Path) -> dict:
    """{"savae", "t5", "tma", "library"} paths of a model folder (the motion library of captured
    takes is optional). No savae.pt is an error; a part the folder's manifest lists but that is gone
    (e.g. ``tma/tma.pt``) is an error naming it; a part the model works without and never had is a
    warning (``part_warnings``)."""
    files = {"savae": d / "savae.pt", "t5": d / "t5", "tma": d / "tma" / "tma.pt", "library": d / "library.npz"}
    if not files["savae"].is_file():
        raise ShapeMoveError(f"{d} has no savae.pt (the SA-VAE): train one with `python -m shapemove train vae`")
    if not files["tma"].is_file() and listed_in_manifest(d, "tma/tma.pt"):
        raise ShapeMoveError(f"model file {files['tma']} is missing (listed in {d / 'manifest.json'}): without it "
                             "best-of-N picking is off and the motions change; copy the model folder again")
    if not files["library"].is_file() and listed_in_manifest(d, "library.npz"):
        raise ShapeMoveError(f"model file {files['library']} is missing (listed in {d / 'manifest.json'}): without "
                             "it no captured take competes and the motions change; copy the model folder again")
    return files


def part_warnings(d: Path) -> list[str]:
    """What a model folder cannot do for lack of an optional part, one sentence each (shown by the
    CLI and the panel beside the motion): no ``tma/tma.pt`` -> no best-of-N picking."""
    tma = Path(d) / "tma" / "tma.pt"
    if tma.is_file():
        return []
    return [f"{tma} is missing: best-of-N picking is off (each prompt gets one sample instead of the best of "
            "several candidates, so motions match their prompts less well); add the model's tma/ folder back "
            "to turn it on"]


MAX_KNOWN_BYTES = 64 << 20  # t5/known_texts.json (50,000 captions at most: a few MB)


def known_actions(model_dir=None, limit: int | None = None) -> list[str]:
    """The actions a model folder's T5 was trained on, most frequent first (``t5/known_texts.json``,
    written at training time); [] for folders without it. Plain JSON, no torch: the Blender panel
    reads it to suggest prompts. A file that is too large or damaged gives [] and a one-line note
    on stderr (once per file version: panels redraw often, each file is read once)."""
    try:
        f = resolve_model_dir(model_dir) / "t5" / "known_texts.json"
        if not f.is_file():
            return []
        key = (str(f), f.stat().st_mtime_ns)
    except (OSError, ShapeMoveError):
        return []
    if key not in _known_cache:
        _known_cache.clear()
        try:
            doc = read_json(f, "known-texts", MAX_KNOWN_BYTES, "copy the model folder again")
            actions = doc.get("actions") if isinstance(doc, dict) else None
            if not isinstance(actions, list):
                raise ShapeMoveError(f"{f}: no list of actions; copy the model folder again")
            _known_cache[key] = [str(a[0]) for a in actions if isinstance(a, list) and a and isinstance(a[0], str)]
        except ShapeMoveError as exc:
            print(f"note: no prompt suggestions: {exc}", file=sys.stderr)
            _known_cache[key] = []
    names = _known_cache[key]
    return names[:limit] if limit else list(names)


_known_cache: dict = {}
