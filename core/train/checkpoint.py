"""Checkpoints: one ``torch.save`` dict written atomically (temp file + ``os.replace``) with a
``metadata`` block that loading checks, so a model is never silently used with another body
model, architecture or data normalization.

metadata = {"kind": "savae", "format": 1, "code_version": "0.1.0", "config": {...},
            "body": "openbody", "data_stats_hash": "sha256...", "mean": [...], "std": [...], "step": N}
Everything is plain Python/tensors, so files load with ``torch.load(weights_only=True)``.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import torch

from ... import __version__
from ..atomic import atomic_path
from ..errors import ShapeMoveError
from ..model_files import add_to_manifest, verify_file

FORMAT = 1


def code_version() -> str:
    return __version__


def stats_hash(mean, std) -> str:
    """sha256 of the float32 bytes of Mean and Std (identifies the data normalization)."""
    h = hashlib.sha256()
    for a in (mean, std):
        a = a.detach().cpu().numpy() if isinstance(a, torch.Tensor) else np.asarray(a)
        h.update(np.ascontiguousarray(a, dtype=np.float32).tobytes())
    return h.hexdigest()


def make_metadata(kind: str, config: dict, body: str, mean, std, step: int = 0, **extra) -> dict:
    f = lambda a: [float(v) for v in (a.detach().cpu().reshape(-1) if isinstance(a, torch.Tensor) else np.asarray(a).reshape(-1))]  # noqa: E731
    return {"kind": kind, "format": FORMAT, "code_version": code_version(), "config": config, "body": body,
            "data_stats_hash": stats_hash(mean, std), "mean": f(mean), "std": f(std), "step": int(step), **extra}


def save_checkpoint(path, payload: dict, metadata: dict) -> Path:
    """Write ``{**payload, "metadata": metadata}`` to ``path`` atomically."""
    path = Path(path)
    with atomic_path(path) as tmp:  # no half-written file or *.tmp left behind (disk full, read-only, ...)
        torch.save({**payload, "metadata": metadata}, tmp)
    add_to_manifest(path.parent, [path])  # loading checks its sha256
    return path


def _flatten(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(_flatten(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = list(v) if isinstance(v, tuple) else v
    return out


def config_differences(a: dict, b: dict, ignore=()) -> list[str]:
    """Keys (dotted) whose values differ between two config dicts, minus ``ignore`` prefixes."""
    fa, fb = _flatten(a), _flatten(b)
    keys = sorted(set(fa) | set(fb))
    return [k for k in keys if fa.get(k) != fb.get(k) and not any(k == i or k.startswith(i + ".") for i in ignore)]


def check_metadata(meta: dict, where: str, kind: str | None = None, body: str | None = None,
                   config: dict | None = None, ignore=(), stats_hash_: str | None = None) -> None:
    """Raise ShapeMoveError naming the first mismatch between ``meta`` and what the caller expects."""
    if not isinstance(meta, dict) or "format" not in meta:
        raise ShapeMoveError(f"{where}: not a ShapeMove checkpoint (no metadata)")
    if meta["format"] > FORMAT:
        raise ShapeMoveError(f"{where}: checkpoint format {meta['format']} is newer than this code ({FORMAT}); update ShapeMove")
    if kind is not None and meta.get("kind") != kind:
        raise ShapeMoveError(f"{where}: is a '{meta.get('kind')}' checkpoint, expected '{kind}'")
    if body is not None and meta.get("body") != body:
        raise ShapeMoveError(f"{where}: trained for body model '{meta.get('body')}', not '{body}'")
    if config is not None:
        diff = config_differences(meta.get("config", {}), config, ignore)
        if diff:
            shown = ", ".join(f"{k} ({_flatten(meta.get('config', {})).get(k)!r} vs {_flatten(config).get(k)!r})" for k in diff[:4])
            raise ShapeMoveError(f"{where}: checkpoint config differs from the requested one: {shown}")
    if stats_hash_ is not None and meta.get("data_stats_hash") != stats_hash_:
        raise ShapeMoveError(f"{where}: checkpoint was trained with another data normalization (Mean/Std differ)")


def load_checkpoint(path, map_location="cpu", **expect) -> dict:
    """Load a checkpoint and ``check_metadata(meta, **expect)`` (kind, body, config, ignore,
    stats_hash_). Returns the whole dict (``["metadata"]`` included)."""
    path = Path(path)
    if not path.is_file():
        raise ShapeMoveError(f"checkpoint not found: {path}")
    verify_file(path)  # sha256 against the manifest beside it: a flipped byte is refused, not used
    try:
        ckpt = torch.load(path, map_location=map_location, weights_only=True)
    except Exception as exc:  # truncated/corrupt/unrelated file
        text = " ".join(str(exc).split()).split(" In PyTorch 2.6")[0]  # drop torch's advice to disable the check
        text = text if len(text) <= 160 else text[:157] + "..."
        raise ShapeMoveError(f"{path}: cannot read checkpoint ({type(exc).__name__}: {text}); a damaged file, or one "
                             "holding code (refused: only tensors and plain values are loaded)") from None
    if not isinstance(ckpt, dict):
        raise ShapeMoveError(f"{path}: not a ShapeMove checkpoint")
    check_metadata(ckpt.get("metadata"), str(path), **expect)
    return ckpt
