"""The motion library file: captured takes, each as it was performed, in one compressed ``.npz``.

Generation offers windows of these takes beside the T5's samples (``generation/captured_takes.py``),
moved onto the requested body by their own rotations, so an action the codec flattens (a front
kick, a jab) still reaches the user as it was captured. The default model ships one
(``weights/default/library.npz``, written by ``python -m shapemove data library``:
``data/library_build.py``).

Arrays (no pickles; strings are fixed-width unicode arrays):

- ``format``: ``FORMAT``;
- ``rotations`` (F,24,3) float16: local rotations (axis-angle, SMPL order) of every frame of every
  take, one after the other; ``root`` (F,3) float32: the root's path (metres, Y up) on the take's
  own body; ``contacts`` (F,4) uint8: the measured foot contacts of joints 7, 8, 10, 11;
- ``starts`` (K+1,) int64: take k is frames ``starts[k]:starts[k+1]``;
- ``betas`` (K,10) float32: the fitted body of each take's performer; ``fps`` (K,) float32;
- ``clip_ids``, ``actions`` (the main action label, ``data/actions.py``; "" for none),
  ``sources`` (who performed it: "HDM05 bd kickLFront 003"), ``licences`` (K,) str;
- ``captions`` (K,) str: each take's captions joined by newlines;
- ``caption_vectors`` (K,E) float16 (optional): the unit mean of each take's captions' text
  embeddings by the model's TMA, ``tma_sha256`` the TMA file they were made with.

``MotionLibrary.load`` reads it bounded (``io/npz_read.read_npz``: headers first, pickles refused,
at most ``MAX_BYTES``) and checks every shape, so a damaged or hostile file is a sentence.

    lib = MotionLibrary.load("weights/default/library.npz")
    take = lib.take(3)          # rotations (T,24,3,3) float32, root, contacts, betas
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..errors import ShapeMoveError

FORMAT = "shapemove-motion-library/1"
MAX_BYTES = 1 << 30          # arrays as read (before float16 -> float32 of one take at a time)
STRINGS = ("clip_ids", "actions", "sources", "licences", "captions")
DATASET_NAMES = {"hdm05": "HDM05", "bandai": "Bandai", "cmu": "CMU", "deepmimic": "DeepMimic", "user": "library"}


def source_name(dataset: str, clip_id: str) -> str:
    """Who performed a take, in a line: "HDM05 bd kickLFront 003" for HDM05's
    ``HDM_bd_kickLFront1Reps_003_120``; "<dataset> <clip id>" for the others."""
    label = DATASET_NAMES.get(dataset, dataset)
    m = re.match(r"HDM_([a-z]+)_(.+)_(\d+)_(\d+)$", clip_id)
    if dataset == "hdm05" and m:
        action = re.sub(r"\d+Reps$", "", m.group(2))
        return f"{label} {m.group(1)} {action} {m.group(3)}"
    return f"{label} {clip_id}"


def short_licence(licence: str) -> str:
    """The licence's name without its attribution: "CC BY-SA 3.0 (HDM05, ...)" -> "CC BY-SA 3.0"."""
    return str(licence).split(" (")[0].strip()


@dataclass
class Take:
    """One take as generation reads it: float32 rotations as matrices."""
    rotations: np.ndarray   # (T,24,3,3)
    root: np.ndarray        # (T,3)
    contacts: np.ndarray    # (T,4) uint8
    betas: np.ndarray       # (10,)
    fps: float
    clip_id: str
    action: str
    source: str
    licence: str
    captions: list[str]

    @property
    def provenance(self) -> str:
        """"captured: HDM05 bd kickLFront 003 (CC BY-SA 3.0)"."""
        return f"captured: {self.source} ({short_licence(self.licence)})"


class MotionLibrary:
    """The arrays of a library file (see the module docstring)."""

    def __init__(self, arrays: dict):
        self.a = arrays
        check_arrays(arrays)

    def __len__(self) -> int:
        return int(len(self.a["starts"]) - 1)

    @property
    def frames(self) -> np.ndarray:
        """(K,) frames of each take."""
        return np.diff(self.a["starts"])

    @property
    def actions(self) -> list[str]:
        return [str(x) for x in self.a["actions"]]

    @property
    def vectors(self) -> np.ndarray | None:
        """(K,E) float32 caption vectors, None when the file has none."""
        v = self.a.get("caption_vectors")
        return None if v is None else np.asarray(v, np.float32)

    @property
    def tma_sha256(self) -> str:
        return str(self.a.get("tma_sha256", ""))

    def captions(self, k: int) -> list[str]:
        return [c for c in str(self.a["captions"][k]).split("\n") if c]

    def take(self, k: int) -> Take:
        """Take ``k``, its rotations as float32 matrices (only this take is converted)."""
        from ..geometry.rotations import axis_angle_to_matrix

        if not 0 <= k < len(self):
            raise ShapeMoveError(f"the motion library has {len(self)} takes, no take {k}")
        lo, hi = int(self.a["starts"][k]), int(self.a["starts"][k + 1])
        return Take(axis_angle_to_matrix(np.asarray(self.a["rotations"][lo:hi], np.float32)).astype(np.float32),
                    np.asarray(self.a["root"][lo:hi], np.float32), np.asarray(self.a["contacts"][lo:hi], np.uint8),
                    np.asarray(self.a["betas"][k], np.float32), float(self.a["fps"][k]), str(self.a["clip_ids"][k]),
                    str(self.a["actions"][k]), str(self.a["sources"][k]), str(self.a["licences"][k]), self.captions(k))

    @classmethod
    def load(cls, path, max_bytes: int = MAX_BYTES) -> "MotionLibrary":
        from ..io.npz_read import read_npz

        path = Path(path)
        if not path.is_file():
            raise ShapeMoveError(f"motion library not found: {path}")
        arrays = read_npz(path, max_bytes=max_bytes, what="motion library")
        try:
            return cls(arrays)
        except ShapeMoveError as exc:
            raise ShapeMoveError(f"{path}: {exc}") from None

    @classmethod
    def from_takes(cls, takes: list[dict], vectors: np.ndarray | None = None, tma_sha256: str = "") -> "MotionLibrary":
        """A library of ``takes``: dicts with ``poses`` (T,24,3) axis-angle, ``root``, ``contacts``,
        ``betas``, ``fps``, ``clip_id``, ``action``, ``source``, ``licence``, ``captions`` (list)."""
        if not takes:
            raise ShapeMoveError("a motion library needs at least one take")
        lengths = [len(t["poses"]) for t in takes]
        arrays = {
            "format": np.str_(FORMAT),
            "rotations": np.concatenate([np.asarray(t["poses"], np.float32) for t in takes]).astype(np.float16),
            "root": np.concatenate([np.asarray(t["root"], np.float32) for t in takes]),
            "contacts": np.concatenate([np.asarray(t["contacts"], np.uint8) for t in takes]),
            "starts": np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64),
            "betas": np.stack([np.asarray(t["betas"], np.float32).reshape(10) for t in takes]),
            "fps": np.asarray([float(t["fps"]) for t in takes], np.float32),
            "clip_ids": np.asarray([str(t["clip_id"]) for t in takes], dtype=np.str_),
            "actions": np.asarray([str(t["action"] or "") for t in takes], dtype=np.str_),
            "sources": np.asarray([str(t["source"]) for t in takes], dtype=np.str_),
            "licences": np.asarray([str(t["licence"]) for t in takes], dtype=np.str_),
            "captions": np.asarray(["\n".join(t["captions"]) for t in takes], dtype=np.str_),
        }
        if vectors is not None:
            arrays["caption_vectors"] = np.asarray(vectors, np.float16)
            arrays["tma_sha256"] = np.str_(tma_sha256)
        return cls(arrays)

    def save(self, path) -> Path:
        """Written atomically, compressed."""
        path = Path(path)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as f:
                np.savez_compressed(f, **self.a)
        return path


def mean_caption_vectors(embed, captions: list[list[str]]) -> np.ndarray:
    """(K,E) the unit mean of each take's caption vectors, ``embed(texts) -> (N,E)`` called once for
    all of them (``captions[k]``: take k's captions, at least one)."""
    flat = [c for cs in captions for c in cs]
    e = np.asarray(embed(flat), np.float32)
    out, i = [], 0
    for cs in captions:
        v = e[i:i + len(cs)].mean(0)
        out.append(v / max(float(np.linalg.norm(v)), 1e-8))
        i += len(cs)
    return np.stack(out).astype(np.float32)


def check_arrays(a: dict) -> None:
    """ShapeMoveError naming the first array that is missing or of the wrong shape or kind."""
    need = ("format", "rotations", "root", "contacts", "starts", "betas", "fps") + STRINGS
    missing = [k for k in need if k not in a]
    if missing:
        raise ShapeMoveError(f"not a motion library: it lacks {', '.join(missing)}")
    if str(a["format"]) != FORMAT:
        raise ShapeMoveError(f"motion library format {str(a['format'])!r}, expected {FORMAT!r}")
    starts = np.asarray(a["starts"])
    if starts.ndim != 1 or len(starts) < 2 or starts.dtype.kind not in "iu" or starts[0] != 0 \
            or (np.diff(starts) <= 0).any():
        raise ShapeMoveError("motion library: starts must rise from 0, one more than the takes")
    k, f = len(starts) - 1, int(starts[-1])
    shapes = {"rotations": (f, 24, 3), "root": (f, 3), "contacts": (f, 4), "betas": (k, 10), "fps": (k,),
              **{s: (k,) for s in STRINGS}}
    for name, shape in shapes.items():
        if tuple(np.shape(a[name])) != shape:
            raise ShapeMoveError(f"motion library: {name} must be {shape}, got {tuple(np.shape(a[name]))}")
    for name in STRINGS:
        if np.asarray(a[name]).dtype.kind != "U":
            raise ShapeMoveError(f"motion library: {name} must be text, got {np.asarray(a[name]).dtype}")
    for name in ("rotations", "root", "betas", "fps"):
        if np.asarray(a[name]).dtype.kind != "f" or not np.isfinite(a[name]).all():
            raise ShapeMoveError(f"motion library: {name} must be finite numbers")
    if (np.asarray(a["fps"]) <= 0).any():
        raise ShapeMoveError("motion library: fps must be positive")
    v = a.get("caption_vectors")
    if v is not None and (np.ndim(v) != 2 or len(v) != k or not np.isfinite(np.asarray(v, np.float32)).all()):
        raise ShapeMoveError(f"motion library: caption_vectors must be ({k}, E) finite numbers")
