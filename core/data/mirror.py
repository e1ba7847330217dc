"""Mirror images of built clips: the body's left and right swapped, reflected across its sagittal
plane (x -> -x in the SMPL frame: Y up, facing +Z, the body's left at +X).

What is mirrored, and how:
- joint positions (shape-aware and normalized): x negated, left/right joints swapped;
- local rotations R (axis-angle in ``poses``): ``M R M`` with ``M = diag(-1, 1, 1)``, left/right
  joints swapped (a rotation about the sagittal axis keeps its sense, about the other two flips);
- root translation: x negated; foot contacts of joints 7, 8, 10, 11: left and right swapped;
- captions: "left" <-> "right", "clockwise" <-> "counter-clockwise", "left-handed" <-> ...
  (``swap_sides``); betas, shape texts and measurements are kept (the body model is symmetric:
  ``tests/test_mirror.py`` checks its rest joints).
The HumanML3D features are recomputed from the mirrored joints and rotations by the builder's own
``ClipProcessor.features``, so a mirrored clip is written exactly like a built one. Mirrored twice
is the identity; a mirrored walk is a walk of the same speed.

Only training clips are mirrored (their copies go to the training split, ids ``ID_mirror``), so
validation and test stay real captured clips.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from .build import ClipProcessor, _write_clip, finalize
from .compose import _read_lines
from .sources import ClipSource

SUFFIX = "_mirror"
PAIRS = [(1, 2), (4, 5), (7, 8), (10, 11), (13, 14), (16, 17), (18, 19), (20, 21), (22, 23)]
_M = np.diag([-1.0, 1.0, 1.0])


class MirroredSource(ClipSource):
    """A ClipSource carrying the licence of the clip it mirrors."""
    source_licence: str = ""

    @property
    def licence(self) -> str:
        return self.source_licence or super().licence


def swap_order(n: int) -> np.ndarray:
    """Index array that swaps the left/right joints among the first ``n`` SMPL joints."""
    order = np.arange(n)
    for a, b in PAIRS:
        if b < n:
            order[a], order[b] = b, a
    return order


def mirror_joints(joints: np.ndarray) -> np.ndarray:
    """(T, J, 3) positions -> mirrored (x negated, left/right swapped)."""
    out = np.asarray(joints)[:, swap_order(joints.shape[1])].copy()
    out[..., 0] *= -1
    return out


def mirror_rotations(rot: np.ndarray) -> np.ndarray:
    """(T, J, 3, 3) local rotations -> mirrored: ``M R M`` on the swapped joints."""
    r = np.asarray(rot)[:, swap_order(rot.shape[1])]
    return (_M @ r @ _M).astype(rot.dtype)


def mirror_contacts(contacts: np.ndarray) -> np.ndarray:
    """(T, 4) contacts of joints 7, 8, 10, 11 -> those of the mirrored clip (8, 7, 11, 10)."""
    return np.asarray(contacts)[:, [1, 0, 3, 2]].copy()


def mirror_features(features: np.ndarray) -> np.ndarray:
    """(T, 263) HumanML3D features -> those of the mirror image, computed on the features alone
    (no joints, no IK): turning and sideways travel negated, the joint positions, velocities and
    local rotations (``M R M`` on the first two columns) of the left and right joints swapped, x
    negated, the contacts of the two feet swapped. What the builder computes from the mirrored
    joints and rotations (``mirror_arrays``), to float precision."""
    from ..motion.features import FEATURE_DIM, NUM_JOINTS, feature_slices as fs

    f = np.asarray(features)
    if f.ndim != 2 or f.shape[1] != FEATURE_DIM:
        raise ShapeMoveError(f"mirror: features must be (T, {FEATURE_DIM}), got {f.shape}")
    T, out = len(f), f.copy()
    out[:, fs["root_rot_vel"]] *= -1
    out[:, fs["root_lin_vel"].start] *= -1
    ric = np.concatenate([np.zeros((T, 1, 3), f.dtype), f[:, fs["ric"]].reshape(T, NUM_JOINTS - 1, 3)], axis=1)
    out[:, fs["ric"]] = mirror_joints(ric)[:, 1:].reshape(T, -1)     # joints 1..21 (the root is not stored)
    out[:, fs["local_vel"]] = mirror_joints(f[:, fs["local_vel"]].reshape(T, NUM_JOINTS, 3)).reshape(T, -1)
    order = swap_order(NUM_JOINTS)
    rot = f[:, fs["rot6d"]].reshape(T, NUM_JOINTS - 1, 6)[:, order[1:] - 1].copy()
    rot[..., [1, 2, 3]] *= -1    # columns c0, c1 of M R M: (c0x, -c0y, -c0z), (-c1x, c1y, c1z)
    out[:, fs["rot6d"]] = rot.reshape(T, -1)
    out[:, fs["contacts"]] = f[:, fs["contacts"]][:, [2, 3, 0, 1]]
    return out


_SIDE_WORDS = [
    ("counter-clockwise", "clockwise"), ("counterclockwise", "clockwise"), ("anti-clockwise", "clockwise"),
    ("anticlockwise", "clockwise"), ("left-handed", "right-handed"), ("left-hand", "right-hand"),
    ("left-footed", "right-footed"), ("leftward", "rightward"), ("lefty", "righty"), ("left", "right"),
]
_SIDE = re.compile(r"\b(" + "|".join(re.escape(w) for pair in _SIDE_WORDS for w in pair) + r")(s?)\b", re.IGNORECASE)
_OTHER = {}
for a, b in _SIDE_WORDS:
    _OTHER.setdefault(a, b)
    _OTHER.setdefault(b, a if not a.startswith(("counter", "anti")) else "counter-clockwise")


def swap_sides(text: str) -> str:
    """The caption of the mirrored clip: side words swapped, their case kept."""
    def repl(m):
        word, plural = m.group(1), m.group(2)
        other = _OTHER[word.lower()]
        if word.isupper():
            other = other.upper()
        elif word[0].isupper():
            other = other[0].upper() + other[1:]
        return other + plural
    return _SIDE.sub(repl, text)


def mirror_arrays(proc: ClipProcessor, data: Path, cid: str) -> dict:
    """The arrays ``build._write_clip`` writes, for the mirror image of built clip ``cid``."""
    from ..geometry.rotations import axis_angle_to_matrix, matrix_to_axis_angle

    load = lambda sub: np.load(data / sub / f"{cid}.npy")  # noqa: E731
    poses, betas = load("poses"), load("betas").astype(np.float32)
    contacts = mirror_contacts(load("contacts")) if (data / "contacts" / f"{cid}.npy").is_file() \
        else np.zeros((len(poses), 4), np.uint8)
    rot = mirror_rotations(axis_angle_to_matrix(poses))
    shaped, normal = mirror_joints(load("new_joints")), mirror_joints(load("norm_joints"))
    if not (len(shaped) == len(normal) == len(rot) == len(contacts)):
        raise ShapeMoveError(f"{data}: clip {cid} has arrays of different lengths")
    transl = load("transl").copy()
    transl[:, 0] *= -1
    return {
        "new_joints": shaped.astype(np.float32), "new_joint_vecs": proc.features(shaped, rot, contacts),
        "norm_joints": normal.astype(np.float32), "norm_joint_vecs": proc.features(normal, rot, contacts),
        "betas": betas, "contacts": contacts.astype(np.uint8),
        "poses": matrix_to_axis_angle(rot).astype(np.float32), "transl": transl.astype(np.float32),
        "ik_error_cm": 0.0, "measure": proc.measure(betas),
    }


def mirror_labels(labels: dict) -> dict:
    """Action labels of the mirror image: any string naming a side is swapped."""
    def sw(v):
        if isinstance(v, str):
            return swap_sides(v)
        if isinstance(v, list):
            return [sw(x) for x in v]
        if isinstance(v, dict):
            return {k: sw(x) for k, x in v.items()}
        return v
    return sw(labels or {})


def mirror_dataset(data, body=None, verbose: bool = True, progress=None, cancel=None,
                   shard: tuple[int, int] = (0, 1)) -> list[str]:
    """Add the mirror image of every training clip (not mirrors themselves, nor clips their source
    mirrored: ``labels.mirrored``) of built dataset
    ``data``; resumable (a clip whose meta exists is skipped). ``shard`` (i, n): only every n-th
    clip from the i-th (n processes can share the work). Returns the ids written."""
    from tqdm import tqdm

    data = Path(data)
    if not (data / "meta").is_dir():
        raise ShapeMoveError(f"{data}: not a built dataset (no meta/ folder); run `data build` first")
    metas = [json.loads(p.read_text(encoding="utf-8")) for p in sorted((data / "meta").glob("*.json"))]
    # a clip the source itself mirrored (DeepMimic's ``*_mirror`` motions: ``labels.mirrored``) has its
    # mirror image in the data already: the clip it was mirrored from
    todo = [m for m in metas if m.get("split") == "train" and not m.get("mirror_of")
            and not (m.get("labels") or {}).get("mirrored")]
    index, count = shard
    if not 0 <= index < count:
        raise ShapeMoveError(f"shard must be i/n with 0 <= i < n, got {index}/{count}")
    todo = todo[index::count]
    proc = ClipProcessor(body)
    written = []
    for i, m in enumerate(tqdm(todo, desc="mirroring", unit="clip", disable=not verbose)):
        if cancel is not None and cancel():
            break
        cid = m["id"] + SUFFIX
        if (data / "meta" / f"{cid}.json").exists():
            continue
        caps = [swap_sides(t) for t in _read_lines(data / "texts" / f"{m['id']}.txt")]
        src = MirroredSource(cid, Path(m.get("source", "")), m.get("dataset", "user"), m.get("subject", ""),
                             caps, mirror_labels(m.get("labels") or {}))
        src.source_licence = m.get("licence", "")
        arrays = mirror_arrays(proc, data, m["id"])
        extra = {k: m[k] for k in ("augmented_from", "composed_from", "phenotype", "parts") if k in m}
        extra["mirror_of"] = m["id"]
        _write_clip(data, cid, arrays, src, "train", extra)
        written.append(cid)
        if progress is not None:
            progress((i + 1) / len(todo), cid)
    finalize(data)
    return written
