"""Rank a folder of motions by a text query with a trained TMA.

A library folder is one of
  * a built dataset folder (``new_joint_vecs/ID.npy`` + ``texts/ID.txt``): every clip, any split;
  * any folder (searched recursively) of ``.npz`` motion files holding ``features`` (T,263) or
    ``joints`` (T,22,3) at 20 fps, and/or ``.bvh`` / ``.amc`` mocap files (converted with
    ``io.mocap.load_smpl22`` + ``motion.features.features_from_joints``). A caption is the
    file's ``prompt`` (npz) or the first line of a same-name ``.txt`` beside it.
The embeddings are cached in the folder as ``.shapemove_index.npz``, keyed by the files' sizes
and modification times and by the TMA checkpoint: the next search with the same files and model
reuses it, any change rebuilds it.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..constants import FPS
from ..errors import ShapeMoveError
from ..generation.model_bundle import DEFAULT_MODEL_DIR
from ..io.mocap import load_smpl22
from ..io.resample import resample_positions

INDEX_NAME = ".shapemove_index.npz"
MOCAP_EXTS = (".bvh", ".amc")


@dataclass
class LibraryIndex:
    folder: Path
    ids: list[str]
    paths: list[str]
    captions: list[str]
    embeddings: np.ndarray            # (N, E) unit vectors
    tma: tuple                        # (model, tokenizer, mean, std)
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (file, reason)
    from_cache: bool = False

    def __len__(self) -> int:
        return len(self.ids)


def _first_line(path: Path) -> str:
    if not path.is_file():
        return ""
    lines = [ln.strip() for ln in path.read_text(encoding="utf-8", errors="replace").splitlines() if ln.strip()]
    return lines[0] if lines else ""


def _is_dataset(folder: Path) -> bool:
    return (folder / "new_joint_vecs").is_dir()


def list_library(folder: Path) -> list[tuple[str, Path, list[Path]]]:
    """(id, motion file, files whose change invalidates the entry) of every motion in ``folder``."""
    if _is_dataset(folder):
        out = []
        for f in sorted((folder / "new_joint_vecs").glob("*.npy")):
            if f.name.endswith(".tmp.npy"):
                continue
            out.append((f.stem, f, [f, folder / "texts" / f"{f.stem}.txt", folder / "Mean.npy", folder / "Std.npy"]))
        return out
    out = []
    for f in sorted(folder.rglob("*")):
        ext = f.suffix.lower()
        if not f.is_file() or f.name == INDEX_NAME or ext not in (".npz", *MOCAP_EXTS):
            continue
        if any(part.startswith(".") for part in f.relative_to(folder).parts):
            continue
        cid = "/".join(f.relative_to(folder).with_suffix("").parts)
        deps = [f, f.with_suffix(".txt")]
        if ext == ".amc":
            deps += sorted(f.parent.glob("*.asf"))
        out.append((cid, f, deps))
    return out


def _stamp(files: list[Path]) -> list:
    return [[str(p), p.stat().st_mtime_ns, p.stat().st_size] if p.is_file() else [str(p), None, None] for p in files]


def _key(entries, tma_file: Path | None) -> str:
    h = hashlib.sha256()
    tma = _stamp([tma_file])[0] if tma_file is not None else None
    h.update(json.dumps({"tma": tma, "files": [[cid, _stamp(deps)] for cid, _, deps in entries]}).encode())
    return h.hexdigest()


def load_motion_features(path: Path) -> tuple[np.ndarray, str]:
    """(features (T,263), caption) of one library file (dataset .npy, motion .npz, BVH/AMC)."""
    from ..motion.features import features_from_joints

    ext = path.suffix.lower()
    caption = _first_line(path.with_suffix(".txt"))
    if ext == ".npy":
        return np.load(path).astype(np.float32), _first_line(path.parent.parent / "texts" / f"{path.stem}.txt")
    if ext == ".npz":
        with np.load(path, allow_pickle=False) as z:
            if "prompt" in z.files and not caption:
                caption = str(z["prompt"])
            if "features" in z.files:
                return np.asarray(z["features"], np.float32), caption
            if "joints" in z.files:
                joints = np.asarray(z["joints"], np.float32)
                fps = float(z["fps"]) if "fps" in z.files else float(FPS)
                if joints.ndim != 3 or joints.shape[1] < 22 or joints.shape[2] != 3:
                    raise ShapeMoveError(f"joints must be (T,22,3), got {joints.shape}")
                if abs(fps - FPS) > 1e-3:
                    joints = resample_positions(joints[:, :22], fps, FPS)
                return features_from_joints(joints[:, :22]), caption
        return features_from_joints(np.asarray(load_smpl22(path).joints, np.float32)), caption  # an AMASS file
    if ext in MOCAP_EXTS:
        return features_from_joints(np.asarray(load_smpl22(path).joints, np.float32)), caption
    raise ShapeMoveError(f"{path}: not a motion file (.npz, .bvh, .amc)")


LIBRARY_CLIP_BYTES = 256 * 2**20   # the most a library clip's arrays may take (a motion, not a dataset)


def library_clip(path: Path):
    """A library's clip that is not a mocap file -> Motion22: a dataset's ``new_joint_vecs/ID.npy``
    (HumanML3D features, 20 fps) or a ``.npz`` that is not an AMASS file (no ``trans``) with
    ``joints`` (T,22,3; a ShapeMove motion file's, at its ``fps``) or ``features`` (T,263). Mocap
    files (.bvh, .amc, AMASS .npz) are returned unchanged (``generation.retarget.source_joints``
    reads them)."""
    from ..io.limits import check_file_size
    from ..io.mocap import Motion22
    from ..io.npz_read import read_npz
    from ..motion.features import joints_from_features

    path = Path(path)
    joints, fps = None, float(FPS)
    if path.suffix.lower() == ".npy":
        check_file_size(path, LIBRARY_CLIP_BYTES, "library feature file")
        try:
            joints = joints_from_features(np.load(path, allow_pickle=False).astype(np.float32))
        except (OSError, ValueError) as exc:
            raise ShapeMoveError(f"{path}: not a HumanML3D feature file ({exc})") from None
    elif path.suffix.lower() == ".npz":
        z = read_npz(path, ("trans", "joints", "fps", "features"), max_bytes=LIBRARY_CLIP_BYTES, what="library motion")
        if "trans" not in z:  # not an AMASS file
            j = z.get("joints")
            if j is not None and j.ndim == 3 and j.shape[1] >= 22 and j.shape[2] == 3:
                joints = j.astype(np.float32)[:, :22]
                fps = float(z["fps"]) if "fps" in z and z["fps"].size == 1 else fps
            elif "features" in z:
                f = np.asarray(z["features"], np.float32)
                if f.ndim != 2 or f.shape[1] != 263:
                    raise ShapeMoveError(f"{path}: features must be (T, 263), got {f.shape}")
                joints = joints_from_features(f)
    if joints is None:
        return path
    if not (np.isfinite(fps) and 1.0 <= fps <= 1000.0):
        raise ShapeMoveError(f"{path}: frame rate {fps} is not a frame rate")
    return Motion22(joints=np.asarray(joints, np.float64), fps=fps, source=str(path), subject=path.stem,
                    offsets=np.zeros((22, 3)))


def library_clips(folder, progress=None, min_frames: int = 8) -> tuple[list[str], list[str], list[np.ndarray], list[Path]]:
    """(ids, captions, features (T,263), files) of the library files that have a caption and at
    least ``min_frames`` frames (what the retrieval memory can use); files without are left out."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ShapeMoveError(f"library folder not found: {folder}")
    ids, captions, feats, files = [], [], [], []
    entries = list_library(folder)
    for i, (cid, path, _) in enumerate(entries):
        try:
            x, caption = load_motion_features(path)
        except ShapeMoveError:
            continue
        if caption.strip() and len(x) >= min_frames and x.ndim == 2 and x.shape[1] == 263 and np.isfinite(x).all():
            ids.append(cid)
            captions.append(caption.strip())
            feats.append(np.asarray(x, np.float32))
            files.append(path)
        if progress is not None:
            progress((i + 1) / max(1, len(entries)), cid)
    if not ids:
        raise ShapeMoveError(f"{folder}: no motion with a caption to add to the memory (a caption is the "
                             "file's prompt or the first line of a same-name .txt)")
    return ids, captions, feats, files


def resolve_tma(tma):
    """(tma tuple, checkpoint file or None) from a path, a load_tma() tuple or None (the default model)."""
    from ..models.tma_embed import load_tma, tma_path

    if isinstance(tma, tuple):
        return tma, None
    if tma is None:
        tma = DEFAULT_MODEL_DIR / "tma" / "tma.pt"
        if not tma.is_file():
            raise ShapeMoveError(f"no TMA given and the default model has none ({tma}); train one with "
                                 "`python -m shapemove train tma` and pass --tma RUN/tma.pt")
    path = tma_path(tma)
    return load_tma(path), path.resolve()


def index_library(folder, tma=None, use_cache: bool = True, progress=None) -> LibraryIndex:
    """Embed every motion of ``folder`` with the TMA (path, load_tma() tuple or None = default).
    Files that cannot be read are skipped (listed in ``index.skipped``)."""
    from ..models.tma_embed import check_features, embed_motions

    folder = Path(folder)
    if not folder.is_dir():
        raise ShapeMoveError(f"motion library folder not found: {folder}")
    tma, tma_file = resolve_tma(tma)
    entries = list_library(folder)
    if not entries:
        raise ShapeMoveError(f"{folder}: no motions found (expected a built dataset folder, or .npz/.bvh/.amc files)")
    key = _key(entries, tma_file)
    cache = folder / INDEX_NAME
    if use_cache and tma_file is not None and cache.is_file():
        try:
            with np.load(cache, allow_pickle=False) as z:
                if str(z["key"]) == key:
                    return LibraryIndex(folder, z["ids"].tolist(), z["paths"].tolist(), z["captions"].tolist(),
                                        z["embeddings"].astype(np.float32), tma,
                                        [tuple(s) for s in json.loads(str(z["skipped"]))], from_cache=True)
        except (OSError, KeyError, ValueError):
            pass  # unreadable or old cache: rebuild it
    ids, paths, captions, feats, skipped = [], [], [], [], []
    for i, (cid, f, _) in enumerate(entries):
        try:
            x, caption = load_motion_features(f)
            feats.append(check_features(x, str(f)))
        except ShapeMoveError as exc:
            skipped.append((str(f), str(exc)))
            continue
        except Exception as exc:  # one bad file must not stop the index
            skipped.append((str(f), f"{type(exc).__name__}: {exc}"))
            continue
        ids.append(cid)
        paths.append(str(f))
        captions.append(caption)
        if progress is not None:
            progress((i + 1) / len(entries), cid)
    if not ids:
        raise ShapeMoveError(f"{folder}: none of the {len(entries)} motion files could be read "
                             f"(first problem: {skipped[0][1]})")
    model, _, mean, std = tma
    emb = embed_motions(model, feats, mean, std)
    index = LibraryIndex(folder, ids, paths, captions, emb, tma, skipped)
    if use_cache and tma_file is not None:
        _save_index(cache, key, index)
    return index


def _save_index(cache: Path, key: str, index: LibraryIndex) -> None:
    try:
        with atomic_path(cache, suffix=".npz") as tmp:
            np.savez(tmp, key=np.array(key), ids=np.array(index.ids, dtype=str), paths=np.array(index.paths, dtype=str),
                     captions=np.array(index.captions, dtype=str), embeddings=index.embeddings,
                     skipped=np.array(json.dumps(index.skipped)))
    except ShapeMoveError:  # a read-only library is still searchable, just not cached
        pass


def check_query(query, top_k: int = 10) -> str:
    """The stripped query; ShapeMoveError when it is empty or ``top_k`` < 1."""
    if not isinstance(query, str) or not query.strip():
        raise ShapeMoveError("the search query is empty: describe a motion, e.g. 'a person waves with the left hand'")
    if top_k < 1:
        raise ShapeMoveError(f"top_k must be at least 1, got {top_k}")
    return query.strip()


def search(index: LibraryIndex, query: str, top_k: int = 10) -> list[tuple[str, float, str, str]]:
    """The ``top_k`` motions closest to ``query``: (id, cosine similarity, path, caption), best first."""
    from ..models.tma_embed import embed_texts

    query = check_query(query, top_k)
    model, tok, _, _ = index.tma
    q = embed_texts(model, tok, [query])[0]
    scores = index.embeddings @ q
    order = np.argsort(-scores, kind="stable")[:top_k]
    return [(index.ids[i], float(scores[i]), index.paths[i], index.captions[i]) for i in order]
