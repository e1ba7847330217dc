"""The one way a trainer's configuration is named: a preset or a JSON file.

Every trainer (SA-VAE, T5, TMA) has the same three presets, so ``--config`` means the same thing
for each ``train KIND`` and in the add-on's Train panel:

- ``tiny``: a smoke run (seconds on a CPU; what the tests use),
- ``small``: CPU-sized (the default),
- ``paper``: the paper's sizes (a GPU run).

A JSON file holds overrides of a preset (each loader says which keys it knows).

    cfg = load_config("T5", "paper", {"tiny": T5TrainConfig.tiny, ...}, from_json)
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from .errors import ShapeMoveError
from .io.limits import read_json

PRESETS = ("tiny", "small", "paper")
DEFAULT_PRESET = "small"
MAX_CONFIG_BYTES = 1 << 20


def load_config(what: str, config, presets: dict[str, Callable], from_json: Callable):
    """``config``: None (the default preset), a name in ``PRESETS`` or a JSON file path ->
    ``presets[name]()`` or ``from_json(data, path)``. ``what`` names the trainer in errors."""
    missing = set(PRESETS) - set(presets)
    if missing:  # a programming error, not the user's
        raise ValueError(f"{what} config: presets {sorted(missing)} are not defined")
    name = DEFAULT_PRESET if config is None else str(config)
    if name in PRESETS:
        return presets[name]()
    path = Path(name)
    if not path.is_file():
        raise ShapeMoveError(f"{what} config {name!r}: use {', '.join(PRESETS)} or a JSON file (not found: {path})")
    data = read_json(path, f"{what} config", MAX_CONFIG_BYTES)
    if not isinstance(data, dict):
        raise ShapeMoveError(f"{path}: a {what} config is a JSON object of settings")
    return from_json(data, path)


def refuse_unknown(data: dict, known, path, what: str) -> None:
    """A config JSON's keys that are not settings (``known``) are refused by name."""
    unknown = set(data) - set(known)
    if unknown:
        raise ShapeMoveError(f"{path}: unknown {what} keys {sorted(unknown)}")
