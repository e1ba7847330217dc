"""Pick the body model from what the user asked for: "openbody" (default) or an SMPL-family file.

``load_body_model(None | "openbody")`` -> the bundled OpenBody; ``load_body_model("/path/SMPL_NEUTRAL.npz")``
(or a folder holding one model) -> ``SMPLFamilyBody``. Models are cached per spec (and file
modification time), so every caller shares one instance: don't modify it in place.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import ShapeMoveError
from .model import BodyModel
from .openbody import OpenBody
from .smpl_family import SMPLFamilyBody

_CACHE: dict[tuple, BodyModel] = {}


def _cache_key(spec) -> tuple:
    if spec is None or (isinstance(spec, str) and spec.strip().lower() in ("", "openbody")):
        return ("openbody",)
    path = Path(spec).expanduser()
    if not path.exists():
        raise ShapeMoveError(f"body model '{spec}' is neither 'openbody' nor an existing .npz/.pkl file or folder "
                             "(SMPL, SMPL-H or SMPL-X model you downloaded yourself)")
    path = path.resolve()
    return ("file", str(path), path.stat().st_mtime_ns)


def load_body_model(spec: str | Path | None = None) -> BodyModel:
    """None / "openbody" -> OpenBody; a path to an SMPL/SMPL-H/SMPL-X .npz/.pkl (or its folder)."""
    key = _cache_key(spec)
    if key not in _CACHE:
        if key[0] == "openbody":
            _CACHE[key] = OpenBody.load()
        else:
            _CACHE[key] = SMPLFamilyBody.load(key[1])
    return _CACHE[key]


def clear_cache() -> None:
    _CACHE.clear()
