"""Find the clips in a source folder or archive, with their subject, licence and captions.

Understands the layout of ``../shared/data`` (``bandai/``, ``hdm05/``, ``cmu/`` -- also the
``cmu/`` inside ``cmu_extra.tar.xz`` --, ``deepmimic/``) and any other folder of BVH / ASF+AMC /
AMASS ``.npz`` files, where a same-name ``.txt`` beside a file holds its captions (one per line).
Every clip's ``labels["actions"]`` lists its canonical actions (``actions.clip_actions``, main one
first); the builder writes the labels into the clip's meta.
"""
from __future__ import annotations

import csv
import json
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ShapeMoveError
from ..io.archive import default_cache_dir, unpack
from . import captions as cap
from .actions import clip_actions

LICENCES = {
    "bandai": "CC BY-NC 4.0 (Bandai Namco Research Inc.)",
    "hdm05": "CC BY-SA 3.0 (HDM05, Mueller et al. 2007)",
    "cmu": "CMU Graphics Lab Motion Capture Database (free for research and commercial use, not for resale)",
    "deepmimic": "MIT (DeepMimic reference motions, Copyright (c) 2018 Xue Bin Peng)",
    "user": "user-supplied (licence as stated by its owner)",
}


@dataclass
class ClipSource:
    id: str
    path: Path
    dataset: str            # bandai | hdm05 | cmu | deepmimic | user
    subject: str
    captions: list[str]
    labels: dict = field(default_factory=dict)
    skeleton_path: Path | None = None  # ASF for an AMC

    @property
    def licence(self) -> str:
        return LICENCES.get(self.dataset, LICENCES["user"])


def open_source(path: Path, cache: Path | None = None) -> Path:
    """A folder as is; an archive unpacked once into the cache. Returns a folder."""
    path = Path(path)
    if path.is_dir():
        return path
    if not path.exists():
        raise ShapeMoveError(f"source not found: {path}")
    name = path.name
    for ext in (".tar.xz", ".tar.gz", ".tgz", ".tar", ".zip"):
        if name.endswith(ext):
            stem = name[: -len(ext)]
            return unpack(path, (cache or default_cache_dir()) / "sources" / stem)
    raise ShapeMoveError(f"{path}: a source must be a folder, .tar.xz, .tar.gz, .tar or .zip")


def _roots(folder: Path) -> list[Path]:
    """The folder itself and, for an unpacked archive, the single top folder inside it."""
    kids = [p for p in folder.iterdir() if p.is_dir() and not p.name.startswith(".")]
    return [folder] + kids


def discover(folder: Path) -> list[ClipSource]:
    folder = Path(folder)
    found: list[ClipSource] = []
    claimed: set[Path] = set()
    for root in _roots(folder):
        if root.name == "bandai" or (root / "dataset-1").is_dir() or (root / "dataset-2").is_dir():
            clips = _bandai(root)
        elif root.name == "hdm05":
            clips = _hdm05(root)
        elif root.name == "cmu" or (root / "cmu_index.csv").is_file():
            clips = _cmu(root)
        elif root.name == "deepmimic" or any(root.glob("humanoid3d_*.txt")):
            clips = _deepmimic(root)
        else:
            continue
        found += clips
        claimed.add(root.resolve())
    if not claimed:
        found = _generic(folder)
    ids = [c.id for c in found]
    if len(ids) != len(set(ids)):
        raise ShapeMoveError(f"{folder}: two clips map to the same id")
    for c in found:
        c.labels.setdefault("actions", clip_actions(c.dataset, c.labels, c.captions))
    return sorted(found, key=lambda c: c.id)


def _bandai(root: Path) -> list[ClipSource]:
    out = []
    for ds in sorted(root.glob("dataset-*")):
        for bvh in sorted((ds / "data").glob("*.bvh")):
            m = re.match(r"(dataset-\d)_(.+)_([a-z-]+)_(\d+)$", bvh.stem)
            if not m:
                continue
            content, style = m.group(2), m.group(3)
            try:
                caps = cap.bandai_captions(content, style, bvh.stem)
            except KeyError:
                caps = [f"A person does {content.replace('-', ' ')} in a {style} style."]
            out.append(ClipSource(bvh.stem, bvh, "bandai", f"bandai-{m.group(1)}", caps,
                                  {"content": content, "style": style}))
    return out


def _hdm05(root: Path) -> list[ClipSource]:
    out = []
    for amc in sorted(root.glob("*/*.amc")):
        m = re.match(r"HDM_([a-z]+)_(.+)_(\d+)_(\d+)$", amc.stem)
        if not m:
            continue
        actor, cls = m.group(1), m.group(2)
        asf = amc.parent / f"HDM_{actor}.asf"
        out.append(ClipSource(amc.stem, amc, "hdm05", f"hdm05-{actor}", cap.hdm05_captions(cls, amc.stem),
                              {"class": cls}, skeleton_path=asf))
    return out


def _cmu(root: Path) -> list[ClipSource]:
    index: dict[str, str] = {}
    if (root / "cmu_index.csv").is_file():
        with open(root / "cmu_index.csv", newline="", encoding="utf-8", errors="replace") as f:
            for row in csv.DictReader(f):
                try:
                    index[f"{int(row['Subject']):02d}_{int(row['Trial #']):02d}"] = row["Motion Description"]
                except (KeyError, ValueError):
                    continue
    kit = {}
    if (root / "kitml_cmu_captions.json").is_file():
        kit = json.loads((root / "kitml_cmu_captions.json").read_text())
    out, seen = [], set()
    files = sorted(root.glob("asfamc/*/*.amc")) + sorted(root.glob("bvh/*/*.bvh"))
    for f in files:  # ASF/AMC first: the BVH copy of the same trial is a conversion of it
        trial = f.stem
        if trial in seen:
            continue
        seen.add(trial)
        subject = trial.split("_")[0]
        asf = f.parent / f"{subject}.asf" if f.suffix == ".amc" else None
        caps = cap.cmu_captions(trial, kit, index.get(trial))
        out.append(ClipSource(f"cmu_{trial}", f, "cmu", f"cmu-{subject}", caps,
                              {"description": index.get(trial, ""), "kit": trial in kit}, skeleton_path=asf))
    return out


def _deepmimic(root: Path) -> list[ClipSource]:
    """DeepMimic's ``humanoid3d_<motion>.txt`` (and ``long/``): one retargeted character, MIT licence."""
    out = []
    for f in sorted(root.glob("humanoid3d_*.txt")) + sorted(root.glob("long/humanoid3d_*.txt")):
        motion = f.stem[len("humanoid3d_"):]
        cid = f"deepmimic_{motion}"
        out.append(ClipSource(cid, f, "deepmimic", "deepmimic", cap.deepmimic_captions(motion, cid),
                              {"motion": motion, "mirrored": motion.endswith("_mirror")}))
    return out


def _generic(folder: Path) -> list[ClipSource]:
    out = []
    for f in sorted(folder.rglob("*")):
        if f.suffix.lower() not in (".bvh", ".amc", ".npz") or not f.is_file():
            continue
        rel = f.relative_to(folder).with_suffix("")
        cid = "__".join(rel.parts)
        txt = f.with_suffix(".txt")
        caps = [ln.strip() for ln in txt.read_text(errors="replace").splitlines() if ln.strip()] if txt.is_file() else []
        asf = None
        if f.suffix.lower() == ".amc":
            asfs = sorted(f.parent.glob("*.asf"))
            asf = asfs[0] if len(asfs) == 1 else next((a for a in asfs if f.stem.startswith(a.stem)), None)
        out.append(ClipSource(cid, f, "user", f.parent.name, caps, {}, skeleton_path=asf))
    return out
