"""Read a HumanML3D-style folder as it is on disk (features are NOT converted here).

Layout: ``new_joint_vecs/<id>.npy`` (T,263) features, ``texts/<id>.txt`` one caption a line as
``caption#tok/POS tok/POS ...#start#end`` (start/end in seconds, 0 meaning the whole clip), and
split files ``train.txt``, ``val.txt``, ``test.txt`` (one clip id a line).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import numpy as np

from ..errors import ShapeMoveError

SPLITS = ("train", "val", "test")


@dataclass
class Caption:
    text: str
    tokens: list
    start: float  # seconds; 0 with end 0 = the whole clip
    end: float


@dataclass
class Clip:
    id: str
    features: np.ndarray  # (T, D) float32 as stored
    captions: list


def parse_caption_line(line: str, source="") -> Caption:
    """``caption#tokens#start#end`` -> Caption (NaN times, as written by HumanML3D, read as 0)."""
    parts = line.rstrip("\n").split("#")
    if len(parts) < 4:
        raise ShapeMoveError(f"{source}: caption line needs 'caption#tokens#start#end': {line[:60]!r}")
    text, tokens, start, end = "#".join(parts[:-3]), parts[-3], parts[-2], parts[-1]
    try:
        s, e = float(start or 0), float(end or 0)
    except ValueError:
        raise ShapeMoveError(f"{source}: caption times are not numbers: {line[:60]!r}") from None
    s, e = (0.0 if math.isnan(s) else s), (0.0 if math.isnan(e) else e)
    return Caption(text.strip(), tokens.split(), s, e)


def read_captions(path) -> list:
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise ShapeMoveError(f"cannot read captions {path}: {exc}") from None
    return [parse_caption_line(line, path) for line in lines if line.strip()]


def read_split(root, split: str) -> list:
    """Clip ids listed in ``<root>/<split>.txt``."""
    if split not in SPLITS:
        raise ShapeMoveError(f"unknown split {split!r}; use one of {', '.join(SPLITS)}")
    path = Path(root) / f"{split}.txt"
    if not path.is_file():
        raise ShapeMoveError(f"HumanML3D split file missing: {path}")
    return [s.strip() for s in path.read_text().splitlines() if s.strip()]


def read_clip(root, clip_id: str) -> Clip:
    root = Path(root)
    feat_path = root / "new_joint_vecs" / f"{clip_id}.npy"
    try:
        feats = np.load(feat_path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise ShapeMoveError(f"cannot read features {feat_path}: {exc}") from None
    if feats.ndim != 2:
        raise ShapeMoveError(f"{feat_path}: features must be (T, D), got {feats.shape}")
    return Clip(clip_id, feats, read_captions(root / "texts" / f"{clip_id}.txt"))


def iter_humanml3d(root, split: str = "train", skip_missing: bool = True) -> Iterator[Clip]:
    """Yield the clips of a split. Ids whose feature or text file is absent are skipped (HumanML3D
    split files list clips some copies lack) unless ``skip_missing=False``."""
    root = Path(root)
    for cid in read_split(root, split):
        have = (root / "new_joint_vecs" / f"{cid}.npy").is_file() and (root / "texts" / f"{cid}.txt").is_file()
        if not have:
            if skip_missing:
                continue
            raise ShapeMoveError(f"HumanML3D clip {cid} listed in {split}.txt has no features or captions")
        yield read_clip(root, cid)
