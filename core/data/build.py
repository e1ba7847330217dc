"""The dataset builder: mocap clips -> HumanML3D-style training data, shape-aware and normalized.

For each clip (see ``sources.discover``):
  1. read it as 22 SMPL joints at 20 fps (``io.mocap.load_smpl22``),
  2. fit the body's betas to the subject's bone lengths (``body.fit``),
  3. IK onto that body -> local rotations + root translation (``body.ik``),
  4. shape-aware motion = FK of the fitted body; normalized motion = the same rotations on the
     canonical body (betas = 0), root trajectory scaled by the pelvis-height ratio (stride follows
     leg length) and put back on the ground,
  5. HumanML3D features of both, captions, shape texts from the mesh measurements.
Bandai clips (one shared skeleton) additionally get retargeted copies on bodies sampled from the
shape space (``AUGMENT_SHARE``). A clip under ``MIN_FRAMES`` but at least ``TAKE_MIN_FRAMES`` long
(a single hop, one arm circle: 0.5 to 1.2 s) trains nothing: it is built whole, without an
augmented copy, into the split ``LIBRARY_SPLIT``, which only the motion library reads
(``library_build.py``); one of a held-out subject is not built at all. Each clip is written
atomically and marked done by its ``meta/ID.json``, so an interrupted build resumes where it stopped.
"""
from __future__ import annotations

import json
import os
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..atomic import atomic_save_npy, atomic_write_text
from ..body.plant import ground_shift, plant_targets
from ..constants import FPS
from ..errors import ShapeMoveError
from ..geometry.rotations import matrix_to_axis_angle
from ..io.mocap import load_smpl22
from ..motion.contacts import detect_contacts
from .shape_text import shape_texts
from .sources import ClipSource, discover, open_source
from .splits import split_of

MIN_FRAMES = 24          # 1.2 s; the SA-VAE trains on the clips of >= 64 frames, the T5 on all
TAKE_MIN_FRAMES = 10     # 0.5 s; a shorter clip is no take the motion library can play
LIBRARY_SPLIT = "library"  # clips too short to train on, kept as captured takes only
AUGMENT_SHARE = 0.5      # fraction of Bandai clips that get one copy on a sampled body
AUGMENT_BETA_CLIP = 2.5  # sampled betas ~ N(0,1) clipped to +-2.5

SUBDIRS = ["new_joints", "new_joint_vecs", "norm_joints", "norm_joint_vecs", "betas", "poses", "transl",
           "contacts", "texts", "shape_texts", "meta"]


@dataclass
class BuildReport:
    built: int = 0
    skipped_done: int = 0
    augmented: int = 0
    failures: list[tuple[str, str]] = field(default_factory=list)
    seconds: float = 0.0
    splits: dict = field(default_factory=dict)

    def summary(self) -> str:
        lines = [f"clips built: {self.built} (+{self.augmented} augmented), already done: {self.skipped_done}, "
                 f"failed: {len(self.failures)}, time: {self.seconds:.0f} s",
                 "splits: " + ", ".join(f"{k} {v}" for k, v in sorted(self.splits.items()))]
        for cid, why in self.failures:
            lines.append(f"  failed {cid}: {why}")
        return "\n".join(lines)


class ClipProcessor:
    """Turns one clip into the arrays of the dataset (no file I/O besides reading the clip)."""

    def __init__(self, body=None, ik_refine_iters: int = 10):
        from ..body.load import load_body_model

        self.body = body if body is not None else load_body_model(None)
        self.ik_refine_iters = ik_refine_iters
        self.rest0 = self.body.rest_joints(None)[0].numpy()
        self._measured: dict[bytes, dict] = {}  # clips of one subject share betas: measure once
        self._probes: dict = {}

    def measure(self, betas: np.ndarray) -> dict:
        from ..body.measure import measure

        key = np.asarray(betas, np.float32).tobytes()
        if key not in self._measured:
            self._measured[key] = {k: float(v) for k, v in measure(self.body, betas).items()}
        return self._measured[key]

    def load(self, clip: ClipSource):
        motion = load_smpl22(clip.path, fps=FPS)
        joints = np.asarray(motion.joints, dtype=np.float32)
        if joints.shape[0] < TAKE_MIN_FRAMES:
            raise ShapeMoveError(f"too short: {joints.shape[0]} frames at {FPS} fps (need {TAKE_MIN_FRAMES})")
        if not np.isfinite(joints).all():
            raise ShapeMoveError("non-finite joint positions")
        return joints

    def fit(self, joints: np.ndarray) -> np.ndarray:
        from ..body.fit import fit_betas_to_clip

        # a plausible body with the least IK joint error for this clip (bone lengths, then layout)
        fit = fit_betas_to_clip(self.body, joints)
        return np.asarray(fit.betas, dtype=np.float32)

    def probe(self, betas: np.ndarray):
        """The ``soles.GroundProbe`` of the body with ``betas`` (cached: clips of a subject share it)."""
        from ..body.soles import GroundProbe

        key = np.asarray(betas, np.float32).tobytes()
        if key not in self._probes:
            if len(self._probes) > 32:
                self._probes.clear()
            self._probes[key] = GroundProbe(self.body, np.asarray(betas, np.float32))
        return self._probes[key]

    def contacts(self, joints: np.ndarray) -> np.ndarray:
        """(T,4) uint8 foot contacts of joints 7, 8, 10, 11 detected on the source mocap."""
        return detect_contacts(joints, FPS)

    def pose_on(self, rotations: np.ndarray, root: np.ndarray, betas: np.ndarray, scale: float,
                contacts: np.ndarray | None = None) -> np.ndarray:
        """(T,22,3) joints: FK of the body with ``betas`` for local ``rotations`` (T,24,3,3) with
        its root on the trajectory ``root`` (T,3) scaled by ``scale`` (stride follows leg length),
        then grounded on the MESH: where a foot is in contact (``contacts`` (T,4) of joints 7, 8,
        10, 11; None = never) its lowest vertex is on y = 0, elsewhere the body keeps its height
        relative to the contact frames around it and never goes under the floor
        (``plant.ground_shift``). ``BodyModel(betas, rotations, joints[:, 0] - rest[0])``
        reproduces the result."""
        import torch

        from ..body.kinematics import posed_joints

        rest = self.body.rest_joints(torch.as_tensor(betas)[None])  # (1,24,3)
        with torch.no_grad():  # window by window: memory does not grow with the take
            joints = posed_joints(self.body, betas, rotations)[:, :22].numpy()
        joints = joints - rest[0, 0].numpy() + (root * scale)[:, None, :]
        per_foot, _, low_all = self.probe(betas).lowest(rotations, joints[:, 0] - rest[0, 0].numpy())
        c = np.zeros((len(joints), 4), np.uint8) if contacts is None else contacts
        joints[..., 1] += ground_shift(per_foot, low_all, c)[:, None]
        return joints.astype(np.float32)

    @staticmethod
    def features(joints: np.ndarray, rotations: np.ndarray, contacts: np.ndarray) -> np.ndarray:
        """(T-1,263) HumanML3D features of (T,22,3) joints grounded on the mesh (``pose_on``: heights
        kept as they are) with local ``rotations`` (T,>=22,3,3); the 4 foot-contact channels hold
        ``contacts`` (T,4) of joints 7, 8, 10, 11."""
        from ..motion.features import posed_features

        return posed_features(joints, rotations, contacts)

    def solve(self, joints: np.ndarray) -> dict:
        """The subject's side of a clip (22 joints at 20 fps): contacts detected on the mocap, betas
        fitted, contact joints' IK targets planted on that body's soles (``plant.plant_targets``),
        IK solved with the clip's torso/girdle joints calibrated (``joint_offsets``: constant offsets
        of the rig's pelvis, hips, spine, neck, collars, head and shoulders from the body's joint
        centres). Returns {"contacts" (T,4) uint8, "betas" (10,) fitted, "rotations" (T,24,3,3),
        "root" (T,3) world root trajectory, "rest" (24,3) rest joints of the fitted body,
        "ik_error_cm" (joint centres vs the mocap), "ik_marker_error_cm" (calibrated points vs the
        mocap), "ik_target_error_cm" (calibrated points vs the planted targets), "ik_offset_max_cm"}."""
        import torch

        from ..body.joint_offsets import marker_points, solve_ik_calibrated
        from ..geometry.torch_ops import forward_kinematics

        contacts = self.contacts(joints)
        fitted = self.fit(joints)
        rest = self.body.rest_joints(torch.as_tensor(fitted)[None])[0].numpy()
        targets, floor = plant_targets(joints, contacts, self.probe(fitted).sole_offsets)
        cal = solve_ik_calibrated(targets, rest, refine_iters=self.ik_refine_iters)
        ik = cal.ik
        rot = np.asarray(ik.rotations, dtype=np.float32)
        fk, _ = forward_kinematics(torch.as_tensor(rot), torch.as_tensor(rest)[None].expand(len(rot), -1, -1),
                                   self.body.parents)
        fk = fk[:, :22].numpy() + ik.transl[:, None]
        mocap = np.asarray(joints, np.float64) - [0.0, floor, 0.0]
        return {"contacts": contacts, "betas": fitted, "rotations": rot, "rest": rest,
                "root": np.asarray(ik.transl, dtype=np.float32) + rest[0],
                "ik_error_cm": float(np.linalg.norm(fk - mocap, axis=-1).mean()) * 100,
                "ik_marker_error_cm": float(np.linalg.norm(
                    marker_points(rot, ik.transl, rest, cal.offsets) - mocap, axis=-1).mean()) * 100,
                "ik_target_error_cm": cal.marker_error_cm, "ik_offset_max_cm": float(cal.offset_cm.max())}

    def stride_scale(self, rest_from: np.ndarray, betas_to: np.ndarray | None) -> float:
        """Root-trajectory scale moving a motion from the body with rest joints ``rest_from`` (24,3)
        to the body ``betas_to`` (None = the canonical body): the pelvis-height (leg length) ratio."""
        import torch

        rest_to = self.rest0 if betas_to is None else self.body.rest_joints(torch.as_tensor(betas_to)[None])[0].numpy()
        pelvis_h = lambda r: r[0, 1] - min(r[7, 1], r[8, 1], r[10, 1], r[11, 1])  # noqa: E731
        return float(pelvis_h(rest_to) / pelvis_h(rest_from))

    def process(self, joints: np.ndarray, betas: np.ndarray | None = None):
        """Arrays of one clip (its 22 joints at 20 fps) on the body ``betas`` (the fitted body when None).

        ``solve`` (contacts, fit, planted IK), then the shape-aware copy on the target body and the
        normalized copy on the canonical body, each grounded on its own mesh (``pose_on``)."""
        import torch

        sol = self.solve(joints)
        rot, root, contacts = sol["rotations"], sol["root"], sol["contacts"]
        target = sol["betas"] if betas is None else betas.astype(np.float32)
        rest_t = self.body.rest_joints(torch.as_tensor(target)[None])[0].numpy()
        scale = self.stride_scale(sol["rest"], target) if betas is not None else 1.0
        shaped = self.pose_on(rot, root, target, scale, contacts)
        normal = self.pose_on(rot, root, np.zeros(10, np.float32), self.stride_scale(sol["rest"], None), contacts)
        m = self.measure(target)
        return {
            "new_joints": shaped, "new_joint_vecs": self.features(shaped, rot, contacts),
            "norm_joints": normal, "norm_joint_vecs": self.features(normal, rot, contacts),
            "betas": target, "contacts": contacts, "rotations": rot, "root": root, "rest": sol["rest"],
            "poses": matrix_to_axis_angle(rot).astype(np.float32),
            "transl": shaped[:, 0] - rest_t[0],  # BodyModel.forward(target, poses, transl) -> shaped
            "ik_error_cm": sol["ik_error_cm"], "ik_target_error_cm": sol["ik_target_error_cm"],
            "ik_marker_error_cm": sol["ik_marker_error_cm"], "ik_offset_max_cm": sol["ik_offset_max_cm"],
            "measure": m,
        }


def _write_clip(out: Path, cid: str, arrays: dict, clip: ClipSource, split: str, extra: dict) -> None:
    for key in ("new_joints", "new_joint_vecs", "norm_joints", "norm_joint_vecs", "betas", "poses", "transl"):
        atomic_save_npy(out / key / f"{cid}.npy", np.asarray(arrays[key], dtype=np.float32))
    atomic_save_npy(out / "contacts" / f"{cid}.npy", np.asarray(arrays["contacts"], dtype=np.uint8))
    atomic_write_text(out / "texts" / f"{cid}.txt", "\n".join(clip.captions) + "\n")
    m = arrays["measure"]
    atomic_write_text(out / "shape_texts" / f"{cid}.txt", "\n".join(shape_texts(m, cid)) + "\n")
    meta = {"id": cid, "source": str(clip.path), "dataset": clip.dataset, "subject": clip.subject,
            "licence": clip.licence, "fps": FPS, "frames": int(arrays["new_joints"].shape[0]),
            "labels": clip.labels, "split": split, "ik_error_cm": round(arrays["ik_error_cm"], 3),
            **{k: round(arrays[k], 3) for k in ("ik_marker_error_cm", "ik_offset_max_cm") if k in arrays},
            "measure": {k: round(v, 1) for k, v in m.items()}, **extra}
    atomic_write_text(out / "meta" / f"{cid}.json", json.dumps(meta))  # written last: marks the clip done


def _augment_body(cid: str, pmap, r2) -> tuple[np.ndarray, np.ndarray | None]:
    """(betas (10,), phenotype (P,) or None) of the sampled body for an augmented copy: drawn from
    phenotypes (``body.phenotype_sample``) when the body model has a phenotype map, else betas
    ~ N(0,1) clipped to +-AUGMENT_BETA_CLIP. Seeded by the whole id: every clip its own body."""
    import hashlib

    seed = int(hashlib.sha1(cid.encode()).hexdigest()[:8], 16)
    rng = np.random.default_rng(seed)
    if pmap is None:
        return np.clip(rng.standard_normal(10), -AUGMENT_BETA_CLIP, AUGMENT_BETA_CLIP).astype(np.float32), None
    from ..body.phenotype_sample import betas_for_phenotypes, sample_phenotypes

    p = sample_phenotypes(pmap, rng, 1)
    return betas_for_phenotypes(pmap, p, rng, r2)[0], p[0]


def _wants_augment(clip: ClipSource, share: float) -> bool:
    import hashlib

    return clip.dataset == "bandai" and int(hashlib.md5(clip.id.encode()).hexdigest()[:8], 16) / 0xFFFFFFFF < share


def build_dataset(sources: list[Path], out: Path, body=None, augment_share: float = AUGMENT_SHARE,
                  limit: int | None = None, only: list[str] | None = None, progress=None, cancel=None,
                  verbose: bool = True, ik_refine_iters: int = 10, shard: tuple[int, int] = (0, 1)) -> BuildReport:
    """Build (or resume building) a dataset folder from mocap sources. See the module docstring."""
    from tqdm import tqdm

    t0 = time.time()
    out = Path(out)
    for d in SUBDIRS:
        (out / d).mkdir(parents=True, exist_ok=True)
    clips: list[ClipSource] = []
    for src in sources:
        clips += discover(open_source(Path(src)))
    if only:
        clips = [c for c in clips if any(c.id.startswith(o) for o in only)]
    if limit:
        clips = clips[:limit]
    index, count = shard
    if not 0 <= index < count:
        raise ShapeMoveError(f"shard must be i/n with 0 <= i < n, got {index}/{count}")
    clips = clips[index::count]  # several processes can build one folder: each takes every n-th clip
    if not clips:
        raise ShapeMoveError(f"no motion clips found in {', '.join(map(str, sources))}")
    proc = ClipProcessor(body, ik_refine_iters=ik_refine_iters)
    pmap = getattr(proc.body, "phenotype_map", None)
    r2 = pmap.r2 if pmap is not None else None
    aug_pheno: dict = {}
    report = BuildReport()
    bar = tqdm(clips, desc="building", unit="clip", disable=not verbose)
    for i, clip in enumerate(bar):
        if cancel is not None and cancel():
            break
        split = split_of(clip.id, clip.subject, clip.dataset)
        todo = [(clip.id, None)]
        if _wants_augment(clip, augment_share):
            aug_betas, aug_pheno[f"{clip.id}_aug"] = _augment_body(clip.id, pmap, r2)
            todo.append((f"{clip.id}_aug", aug_betas))
        todo = [(cid, b) for cid, b in todo if not (out / "meta" / f"{cid}.json").exists()]
        if not todo:
            report.skipped_done += 1
            continue
        try:
            joints = proc.load(clip)
            if len(joints) < MIN_FRAMES:   # a take for the library only, never of a held-out subject
                if split == "test":
                    raise ShapeMoveError(f"too short: {len(joints)} frames at {FPS} fps (need {MIN_FRAMES}; "
                                         "a shorter take of a held-out subject is not kept)")
                split, todo = LIBRARY_SPLIT, [(cid, b) for cid, b in todo if b is None]
            for cid, b in todo:
                arrays = proc.process(joints, b)
                extra = {"augmented_from": clip.id} if b is not None else {}
                if aug_pheno.get(cid) is not None:
                    extra["phenotype"] = {n: round(float(v), 4) for n, v in zip(pmap.names, aug_pheno[cid])}
                _write_clip(out, cid, arrays, clip, split, extra)
                if b is None:
                    report.built += 1
                else:
                    report.augmented += 1
        except ShapeMoveError as exc:
            report.failures.append((clip.id, str(exc)))
        except Exception as exc:  # a bad clip must not stop the build: report it with its reason
            report.failures.append((clip.id, f"{type(exc).__name__}: {exc}"))
            if os.environ.get("SHAPEMOVE_DEBUG"):
                traceback.print_exc()
        if progress is not None:
            progress((i + 1) / len(clips), clip.id)
    report.splits = finalize(out)
    report.seconds = time.time() - t0
    path = out / ("build_report.txt" if count == 1 else f"build_report.shard-{index}-of-{count}.txt")
    earlier = path.read_text() if path.is_file() else ""   # every run's report is kept, newest last
    atomic_write_text(path, earlier + report.summary() + "\n")
    return report


def finalize(out: Path) -> dict[str, int]:
    """meta.jsonl, split lists and Mean/Std (over the training split) from the per-clip files;
    returns the clips of each split (train, val, test and ``LIBRARY_SPLIT``, which has no list)."""
    from ..motion.features import mean_std

    metas = [json.loads(p.read_text()) for p in sorted((out / "meta").glob("*.json"))]
    atomic_write_text(out / "meta.jsonl", "".join(json.dumps(m) + "\n" for m in metas))
    for s in ("train", "val", "test"):
        atomic_write_text(out / f"{s}.txt", "".join(m["id"] + "\n" for m in metas if m["split"] == s))
    train = [m["id"] for m in metas if m["split"] == "train"] or [m["id"] for m in metas]
    if train:
        feats = [np.load(out / "new_joint_vecs" / f"{cid}.npy") for cid in train]
        feats += [np.load(out / "norm_joint_vecs" / f"{cid}.npy") for cid in train]
        mean, std = mean_std(feats)
        atomic_save_npy(out / "Mean.npy", np.asarray(mean, np.float32))
        atomic_save_npy(out / "Std.npy", np.asarray(std, np.float32))
    return {s: sum(m["split"] == s for m in metas) for s in ("train", "val", "test", LIBRARY_SPLIT)}
