"""Write the motion library (``data/motion_library.py``) from a built dataset.

    python -m shapemove data library --data data/built --out weights/default/library.npz

The takes are the dataset's captured clips of the training and validation splits as performed,
and those too short to train on (``build.LIBRARY_SPLIT``: a single hop, one arm circle; not a
stride of a gait): no shape-augmented copies, composed clips or mirror images (generation mirrors
a take itself when the words name the other side), never the test split (held out for evaluation). Each keeps its
rotations, root path, measured contacts, fitted betas, captions, main action, performer and
licence. The frequent actions (``FREQUENT``: walks, runs, jogs, raised hands, waves) keep
``FREQUENT_TAKES`` takes each, drawn round-robin over their (source, label) groups so that the
kept ones differ from each other; every take of every other action is kept. A take whose root jumps
from frame to frame (``jerky``: a broken capture) is left out. With the model's TMA
each take also gets the unit mean of its captions' TMA text embeddings (what a prompt is compared
with when takes compete, ``generation/captured_takes.py``).
"""
from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from .build import LIBRARY_SPLIT
from .built_meta import is_real
from .motion_library import MotionLibrary, mean_caption_vectors, source_name

SPLITS = ("train", "val", LIBRARY_SPLIT)
FREQUENT = ("walk", "run", "jog", "raise hand", "wave")
FREQUENT_TAKES = 96
JERK = 15.0   # m/s^2: the median change of a take's root speed from frame to frame over which its capture is broken


def jerky(root, fps: float) -> bool:
    """Whether a take's root jumps from frame to frame: the median change of its horizontal speed
    between frames over ``JERK`` m/s^2 (CMU 07_12, "brisk walk": 28, its pelvis from 0.58 to 0.90 m
    and its speed 0.1 to 5.5 m/s from one frame to the next; the data's other takes, dashes and
    flips included, at most 5.4)."""
    r = np.asarray(root, np.float64)[:, [0, 2]]
    if len(r) < 3:
        return False
    speed = np.linalg.norm(np.diff(r, axis=0), axis=1) * fps
    return float(np.median(np.abs(np.diff(speed)))) * fps > JERK


def library_metas(data) -> list[dict]:
    """The metas of the captured takes a library holds (see the module docstring), sorted by id: of
    the clips too short to train on, not those of a gait (a 0.65 s sprint is a stride, not a take to
    walk on from); no take whose root jumps from frame to frame (``jerky``)."""
    from ..plan.vocabulary import GAITS

    data = Path(data)
    if not (data / "meta").is_dir():
        raise ShapeMoveError(f"{data} is not a built dataset (no meta/ folder): run `python -m shapemove data build`")
    out = []
    for p in sorted((data / "meta").glob("*.json")):
        m = json.loads(p.read_text(encoding="utf-8"))
        if m.get("split") in SPLITS and is_real(m):
            path = data / "transl" / f"{m['id']}.npy"
            if m["split"] == LIBRARY_SPLIT and main_action(m) in GAITS or \
                    path.is_file() and jerky(np.load(path, allow_pickle=False), float(m.get("fps", 20))):
                continue
            out.append(m)
    return out


def main_action(meta: dict) -> str:
    acts = (meta.get("labels") or {}).get("actions") or []
    return str(acts[0]) if acts else ""


def thinned(metas: list[dict], frequent=FREQUENT, keep: int = FREQUENT_TAKES) -> list[dict]:
    """``metas`` with each frequent action cut to ``keep`` takes, taken one per (dataset, label)
    group in turn (the longest of a group first), so the kept takes are of different sources and
    styles; the others all kept. Order: by id."""
    by_action = defaultdict(list)
    for m in metas:
        by_action[main_action(m)].append(m)
    out = []
    for action, ms in by_action.items():
        if action not in frequent or len(ms) <= keep:
            out += ms
            continue
        groups = defaultdict(list)
        for m in sorted(ms, key=lambda m: (-int(m.get("frames", 0)), m["id"])):
            groups[(m.get("dataset"), json.dumps(m.get("labels", {}), sort_keys=True))].append(m)
        queues = [groups[g] for g in sorted(groups)]
        chosen = []
        while len(chosen) < keep:
            for q in queues:
                if q and len(chosen) < keep:
                    chosen.append(q.pop(0))
        out += chosen
    return sorted(out, key=lambda m: m["id"])


def read_take(data: Path, meta: dict, body) -> dict:
    """One clip's arrays as ``MotionLibrary.from_takes`` reads them (root = the posed root joint)."""
    import torch

    cid = meta["id"]
    load = lambda sub: np.load(data / sub / f"{cid}.npy", allow_pickle=False)  # noqa: E731
    poses, transl, betas = load("poses"), load("transl"), load("betas").astype(np.float32)
    contacts = load("contacts") if (data / "contacts" / f"{cid}.npy").is_file() else np.zeros((len(poses), 4), np.uint8)
    with torch.no_grad():
        rest = body.rest_joints(torch.as_tensor(betas)[None])[0].numpy()
    captions = [c.strip() for c in (data / "texts" / f"{cid}.txt").read_text(encoding="utf-8").splitlines() if c.strip()]
    return {"poses": poses, "root": (transl + rest[0]).astype(np.float32), "contacts": contacts.astype(np.uint8),
            "betas": betas, "fps": float(meta.get("fps", 20)), "clip_id": cid, "action": main_action(meta),
            "source": source_name(meta.get("dataset", ""), cid), "licence": meta.get("licence", ""),
            "captions": captions}


def caption_vectors(tma, takes: list[dict]) -> np.ndarray:
    """(K,E) unit mean TMA text embedding of each take's captions (``tma``: ``load_tma``'s tuple)."""
    from ..models.tma_embed import embed_texts

    return mean_caption_vectors(lambda texts: embed_texts(tma[0], tma[1], texts),
                                [t["captions"] or [t["action"] or "a person moves"] for t in takes])


def build_library(data, out, body=None, tma_file=None, progress=None, cancel=None) -> MotionLibrary:
    """Write the library of the built dataset ``data`` to ``out`` (see the module docstring);
    ``tma_file``: the model's ``tma.pt`` for the caption vectors (None: none). ``progress(fraction,
    clip id)``; ``cancel()`` stops it with nothing written."""
    from ..body.load import load_body_model

    data = Path(data)
    body = body if body is not None else load_body_model(None)
    metas = thinned(library_metas(data))
    if not metas:
        raise ShapeMoveError(f"{data} holds no captured clips of the training or validation splits")
    takes = []
    for i, m in enumerate(metas):
        if cancel is not None and cancel():
            raise ShapeMoveError("motion library cancelled: nothing written")
        takes.append(read_take(data, m, body))
        if progress is not None:
            progress((i + 1) / len(metas), m["id"])
    vectors, sha = None, ""
    if tma_file is not None:
        from ..model_files import sha256_file
        from ..models.tma_embed import load_tma

        vectors, sha = caption_vectors(load_tma(tma_file), takes), sha256_file(Path(tma_file))
    lib = MotionLibrary.from_takes(takes, vectors, sha)
    lib.save(out)
    return lib
