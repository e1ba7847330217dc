"""Compositions "A, then B": two clips of a BUILT dataset joined into a new clip of it.

The composed clip lives on A's body (A's betas): A's local rotations, then a short blended
transition, then B's rotations. B's root path is scaled to A's leg length (as the builder scales
retargeted strides), turned about +Y so B starts facing where A is facing, and moved so it
continues from A's position. The transition cross-fades the last ``BLEND_FRAMES`` frames of A with
the first of B (0.5 s at 20 fps): joint rotations by slerp, root position linearly, with a
smoothstep weight. FK, grounding on the mesh and the HumanML3D features come from the builder's
``ClipProcessor`` (``pose_on``, ``features``), so a composed clip is written exactly like a built
one (``build._write_clip``) and ``build.finalize`` refreshes the split lists and Mean/Std.

Pairs: A's main action is drawn with probability ~ sqrt(number of clips with it) (so rare actions
such as a cartwheel appear in compositions without drowning the common ones), then a clip of it; B
likewise among the other actions; a pair is redrawn unless A ends and B starts upright
(``upright``). Only training clips (not augmented, not composed) are joined, and composed clips go
to the training split, so validation/test clips never leak into training. Captions say "X, then
Y" in several phrasings ("a person walks forward, then waves.", "first a person walks forward,
then waves.", "a person walks forward and then waves.", "a person walks forward before waving.",
...), with X and Y taken from the clips' own generated captions; meta ``labels["actions"]`` lists
A's actions then B's; ``composed_from`` names both clips. Deterministic for a given ``seed``.
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from ..geometry.rotations import (axis_angle_to_matrix, matrix_to_axis_angle, matrix_to_quaternion,
                                  quaternion_to_matrix, slerp, yaw_matrix)
from .actions import ACTIONS
from .build import ClipProcessor, _write_clip, finalize
from .captions import _pick, _tidy, progressive
from .sources import ClipSource

BLEND_FRAMES = 10          # 0.5 s at 20 fps
MAX_PART_FRAMES = 80       # each part at most 4 s: a composed clip stays <= 7.5 s (the T5's 50 codes = 10 s)
MIN_PART_FRAMES = 24
_SUBJECT = re.compile(r"^(a person|someone|the person|a man|a woman|a human) (?!is )(.+?)\.?$", re.IGNORECASE)


@dataclass
class Part:
    id: str
    meta: dict
    rotations: np.ndarray   # (T,24,3,3) local
    root: np.ndarray        # (T,3) world pelvis trajectory
    betas: np.ndarray       # (10,)
    contacts: np.ndarray    # (T,4) uint8
    vp: str                 # verb phrase for captions ("walks forward happily")


class ComposedSource(ClipSource):
    """A ClipSource whose licence is that of both parts."""

    def __init__(self, cid: str, a: Part, b: Part, captions: list[str], labels: dict):
        datasets = sorted({a.meta.get("dataset", "user"), b.meta.get("dataset", "user")})
        super().__init__(cid, Path(a.meta.get("source", "")), "+".join(datasets), "composed", captions, labels)
        self._licences = sorted({a.meta.get("licence", ""), b.meta.get("licence", "")} - {""})

    @property
    def licence(self) -> str:
        return " + ".join(self._licences) or "unknown"


def verb_phrase(captions: list[str], actions: list[str]) -> str | None:
    """The verb phrase of a clip's first generated caption ("A person walks forward." -> "walks
    forward"), else its main action's phrase, else None."""
    for c in captions:
        m = _SUBJECT.match(c.strip())
        if m:
            vp = m.group(2).strip().rstrip(".")
            if ":" not in vp and " then " not in vp:
                return vp[0].lower() + vp[1:]
    for a in actions:
        if a in ACTIONS:
            return ACTIONS[a].phrases[0]
    return None


def composed_captions(cid: str, x: str, y: str, n: int = 5) -> list[str]:
    """Several phrasings of "X, then Y" (verb phrases x, y in the third person present)."""
    y_ing = progressive(y)
    subjects = ["a person", "someone", "a man", "a woman", "the person"]
    options = []
    for s in subjects:
        options += [f"{s} {x}, then {y}.", f"{s} {x} and then {y}.", f"first {s} {x}, then {y}.",
                    f"{s} {x} before {y_ing}.", f"{s} {x}, and after that {y}."]
    first = f"a person {x}, then {y}."
    return [_tidy(s) for s in [first] + _pick(cid, [o for o in options if o != first], n - 1)]


def _read_lines(path: Path) -> list[str]:
    return [ln.strip() for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip()] if path.is_file() else []


def load_part(data: Path, cid: str, meta: dict, body, first: bool) -> Part:
    """A clip of the built dataset as rotations + root path; ``first``: keep its END (A), else its START (B)."""
    import torch

    poses = np.load(data / "poses" / f"{cid}.npy")
    transl = np.load(data / "transl" / f"{cid}.npy")
    betas = np.load(data / "betas" / f"{cid}.npy").astype(np.float32)
    cpath = data / "contacts" / f"{cid}.npy"
    contacts = np.load(cpath).astype(np.uint8) if cpath.is_file() else np.zeros((len(poses), 4), np.uint8)
    if poses.ndim != 3 or poses.shape[1:] != (24, 3) or len(transl) != len(poses) or len(contacts) != len(poses):
        raise ShapeMoveError(f"{data}: clip {cid} has inconsistent poses/transl/contacts arrays")
    rest0 = body.rest_joints(torch.as_tensor(betas)[None])[0, 0].numpy()
    sl = slice(-MAX_PART_FRAMES, None) if first else slice(0, MAX_PART_FRAMES)
    caps = _read_lines(data / "texts" / f"{cid}.txt")
    vp = verb_phrase(caps, (meta.get("labels") or {}).get("actions", []))
    return Part(cid, meta, axis_angle_to_matrix(poses[sl]), (transl + rest0)[sl], betas, contacts[sl], vp or "")


def _yaw(root_rot: np.ndarray) -> float:
    """Heading (radians about +Y) of a root rotation: where the body's forward (+Z) points."""
    f = root_rot[:, 2]
    return float(np.arctan2(f[0], f[2]))


def join(a: Part, b: Part, scale_b: float, blend: int = BLEND_FRAMES):
    """(rotations (T,24,3,3), root (T,3), contacts (T,4)) of A then B with a cross-faded transition."""
    k = int(min(blend, len(a.rotations) - 1, len(b.rotations) - 1))
    start = len(a.rotations) - k                          # first frame of A that is blended
    turn = yaw_matrix(_yaw(a.rotations[start, 0]) - _yaw(b.rotations[0, 0]))
    rb = b.rotations.copy()
    rb[:, 0] = turn @ rb[:, 0]
    rel = (b.root - b.root[0]) * scale_b
    pb = rel @ turn.T
    pb[:, [0, 2]] += a.root[start, [0, 2]]
    pb[:, 1] = b.root[:, 1] * scale_b
    w = np.arange(1, k + 1) / (k + 1)
    w = w * w * (3 - 2 * w)                               # smoothstep
    qa = matrix_to_quaternion(a.rotations[start:])
    qb = matrix_to_quaternion(rb[:k])
    mid_rot = quaternion_to_matrix(slerp(qa, qb, np.broadcast_to(w[:, None], qa.shape[:-1])))
    mid_root = (1 - w)[:, None] * a.root[start:] + w[:, None] * pb[:k]
    mid_contacts = np.where((w < 0.5)[:, None], a.contacts[start:], b.contacts[:k])
    rot = np.concatenate([a.rotations[:start], mid_rot, rb[k:]])
    root = np.concatenate([a.root[:start], mid_root, pb[k:]])
    contacts = np.concatenate([a.contacts[:start], mid_contacts, b.contacts[k:]]).astype(np.uint8)
    return rot.astype(np.float32), root.astype(np.float32), contacts


def posed_arrays(proc, rot: np.ndarray, root: np.ndarray, betas: np.ndarray, contacts: np.ndarray, rest=None) -> dict:
    """The arrays ``build._write_clip`` writes for local rotations ``rot`` (T,24,3,3) and world root
    path ``root`` (T,3) on the body ``betas`` (its rest joints ``rest`` when known): FK and grounding
    on the mesh for that body and for the canonical one (stride scaled with leg length), and the
    features of both (``ClipProcessor``)."""
    import torch

    if rest is None:
        rest = proc.body.rest_joints(torch.as_tensor(betas)[None])[0].numpy()
    shaped = proc.pose_on(rot, root, betas, 1.0, contacts)
    normal = proc.pose_on(rot, root, np.zeros(10, np.float32), proc.stride_scale(rest, None), contacts)
    return {
        "new_joints": shaped, "new_joint_vecs": proc.features(shaped, rot, contacts),
        "norm_joints": normal, "norm_joint_vecs": proc.features(normal, rot, contacts),
        "betas": betas, "contacts": contacts, "poses": matrix_to_axis_angle(rot).astype(np.float32),
        "transl": shaped[:, 0] - rest[0], "ik_error_cm": 0.0, "measure": proc.measure(betas),
    }


def compose_arrays(proc, a: Part, b: Part) -> dict:
    """The arrays ``build._write_clip`` writes, for A then B on A's body (``posed_arrays``)."""
    import torch

    rest_b = proc.body.rest_joints(torch.as_tensor(b.betas)[None])[0].numpy()
    rot, root, contacts = join(a, b, proc.stride_scale(rest_b, a.betas))
    return posed_arrays(proc, rot, root, a.betas, contacts)


def upright(data: Path, meta: dict, end: bool) -> bool:
    """Whether the clip's last (``end``) or first frame stands upright: pelvis at >= 75 % of the
    leg length above the floor and the head >= 35 % of it above the pelvis. A transition of 0.5 s
    cannot get a body up from the floor, so only upright ends are joined."""
    j = np.load(data / "new_joints" / f"{meta['id']}.npy", mmap_mode="r")
    f = np.asarray(j[-1 if end else 0], dtype=np.float64)
    leg = float((meta.get("measure") or {}).get("leg_length_cm", 85.0)) / 100.0
    return f[0, 1] >= 0.75 * leg and f[15, 1] - f[0, 1] >= 0.35 * leg


def _candidates(data: Path) -> list[dict]:
    metas = [json.loads(p.read_text(encoding="utf-8")) for p in sorted((data / "meta").glob("*.json"))]
    return [m for m in metas if m.get("split") == "train" and not m.get("augmented_from")
            and not m.get("composed_from") and (m.get("labels") or {}).get("actions")
            and int(m.get("frames", 0)) >= MIN_PART_FRAMES]


def compose_dataset(data, count: int, seed: int = 0, body=None, verbose: bool = True) -> list[str]:
    """Add ``count`` composed clips to the built dataset ``data`` (resumable: ids are
    ``comp{seed}_{i:05d}`` and a clip whose meta exists is skipped). Returns the ids written."""
    from tqdm import tqdm

    data = Path(data)
    if not (data / "meta").is_dir():
        raise ShapeMoveError(f"{data}: not a built dataset (no meta/ folder); run `data build` first")
    if count < 1:
        raise ShapeMoveError(f"--count must be at least 1, got {count}")
    cands = _candidates(data)
    if len(cands) < 2:
        raise ShapeMoveError(f"{data}: needs at least 2 training clips with action labels to compose")
    rng = np.random.default_rng(seed)
    by_action: dict[str, list[dict]] = {}
    for m in cands:
        by_action.setdefault(m["labels"]["actions"][0], []).append(m)
    names = sorted(by_action)
    weight = np.sqrt([len(by_action[a]) for a in names])   # rare actions get more than their share
    proc = ClipProcessor(body)
    written, skipped, i, draws = [], 0, 0, 0
    bar = tqdm(total=count, desc="composing", unit="clip", disable=not verbose)
    while i < count and draws < 50 * count:
        draws += 1
        ia = int(rng.choice(len(names), p=weight / weight.sum()))
        wb = weight.copy()
        if len(names) > 1:
            wb[ia] = 0.0
        ib = int(rng.choice(len(names), p=wb / wb.sum()))
        ma = by_action[names[ia]][int(rng.integers(len(by_action[names[ia]])))]
        mb = by_action[names[ib]][int(rng.integers(len(by_action[names[ib]])))]
        main_a = names[ia]
        if not (upright(data, ma, end=True) and upright(data, mb, end=False)):
            skipped += 1
            continue
        cid = f"comp{seed}_{i:05d}"
        i += 1
        bar.update(1)
        if (data / "meta" / f"{cid}.json").exists():
            continue
        a = load_part(data, ma["id"], ma, proc.body, first=True)
        b = load_part(data, mb["id"], mb, proc.body, first=False)
        if not a.vp or not b.vp:
            continue
        labels = {"actions": list(dict.fromkeys(ma["labels"]["actions"] + mb["labels"]["actions"])),
                  "sequence": [main_a, mb["labels"]["actions"][0]]}
        src = ComposedSource(cid, a, b, composed_captions(cid, a.vp, b.vp), labels)
        arrays = compose_arrays(proc, a, b)
        _write_clip(data, cid, arrays, src, "train", {"composed_from": [a.id, b.id], "blend_frames": BLEND_FRAMES})
        written.append(cid)
    bar.close()
    finalize(data)
    if verbose and skipped:
        print(f"{skipped} drawn pairs skipped: a part starts or ends off its feet (lying, crawling)")
    return written
