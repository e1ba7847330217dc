"""SA-VAE retargeting against naive retargeting, on the same clips and target bodies.

Every clip is moved onto every target body both ways (``generation.retarget``) and scored with
``evaluate_motion`` on the target body: bone-length error against the TARGET body's bones (the
SA-VAE's decoded joints; for naive retargeting the joints are the target body's FK, so ~0 by
construction), penetrate, float, skate and dynamic stability of the posed mesh, and the slide of
the feet the SOURCE plants (``physics.stance_slide`` on the posed joints, with the contacts detected
on the captured joints: the same frames for both sides; floating does not hide it). Metrics are
pooled over all (clip, body) motions, frame-weighted (``report.aggregate``; the stance slide over
the planted joint-pairs).

    compare_retargeting("DATA", "runs/vae", ["cmu_09_01", "walk.bvh"], [np.zeros(10), tall_betas])
    -> {"savae": {KEYS...}, "naive": {KEYS...}}
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from .evaluate import evaluate_motion
from .report import aggregate

KEYS = ("bone_err_mm", "penetrate_cm", "float_cm", "skate_pct", "dyn_stable_pct", "penetrate_all_cm", "float_all_cm",
        "skate_joints_pct", "stance_slide_mm", "stance_slide_pct")
STANCE_KEYS = ("stance_slide_mm", "stance_slide_pct")   # weighted by the contact joint-pairs, n_stance


def source_motion(data, clip):
    """A clip id of the dataset folder ``data`` (its shape-aware joints ``new_joints``) or a mocap
    file path -> what ``generation.retarget`` accepts (a Motion22 or the path)."""
    from ..io.mocap import Motion22

    if isinstance(clip, Path) or (isinstance(clip, str) and Path(clip).suffix.lower() in (".bvh", ".amc", ".npz")):
        return Path(clip)
    if data is None:
        raise ShapeMoveError(f"clip {clip!r} is not a motion file and no dataset folder was given")
    p = Path(data) / "new_joints" / f"{clip}.npy"
    if not p.is_file():
        raise ShapeMoveError(f"{data}: no clip {clip!r} (new_joints/{clip}.npy missing)")
    joints = np.load(p).astype(np.float32)
    return Motion22(joints=joints, fps=float(FPS), source=str(clip), subject="", offsets=np.zeros((22, 3)))


def _score(body, motion, betas, contacts=None) -> dict:
    """``evaluate_motion`` of a Motion on ``body`` + ``stance``: the slide of its posed joints
    (FK, what the rig plays) where ``contacts`` (>= T,4; the source's) plant a foot."""
    from ..geometry.rotations import axis_angle_to_matrix

    rot = axis_angle_to_matrix(motion.poses)
    joints = motion.network_joints if motion.network_joints is not None else motion.joints  # decoded, if any
    row = evaluate_motion(body, betas, rot, motion.transl, joints=joints, target_betas=betas)
    return row if contacts is None else {**row, **stance(motion.joints, contacts)}


def stance(joints, contacts) -> dict:
    """(T,22,3) posed joints + (>= T,4) known contacts -> {stance_slide_mm, stance_slide_pct,
    n_stance} (``physics.stance_slide``)."""
    from .physics import stance_slide

    j = np.asarray(joints)
    mm, pct = stance_slide(j, np.asarray(contacts)[:len(j)])
    return {"stance_slide_mm": mm.value, "stance_slide_pct": pct.value, "n_stance": mm.count}


def source_score(body, data, clip):
    """The captured motion on its own fitted body (the dataset's ``poses``/``transl``/``betas``),
    scored as the retargeted ones: the level of penetrate/float/skate/stability the capture itself
    reaches. None for a mocap file (no fitted body stored)."""
    from ..geometry.rotations import axis_angle_to_matrix

    if data is None or not (Path(data) / "poses" / f"{clip}.npy").is_file():
        return None
    load = lambda sub: np.load(Path(data) / sub / f"{clip}.npy").astype(np.float32)  # noqa: E731
    betas = load("betas")
    from ..generation.retarget import source_contacts

    row = evaluate_motion(body, betas, axis_angle_to_matrix(load("poses")), load("transl"), target_betas=betas)
    joints = load("new_joints")
    return {**row, **stance(joints, source_contacts(joints))}


def compare_retargeting(data, checkpoint, clips, target_betas_list, body=None, ik_refine_iters: int = 10,
                        progress=None, plant_source_contacts: bool = True, search: bool = True,
                        fallback_mm: float | None = None) -> dict:
    """{"savae": metrics, "auto": metrics, "naive": metrics, "naive_frame": metrics, "swap": metrics,
    "source": metrics}
    (``KEYS`` + "clips", "bodies"; "naive_frame": ``ground_each_frame`` of naive, each frame's
    lowest point on the floor: naive without its hovering, which hides slides from the 5 cm contact
    line of ``skate``; "swap": ``swap_betas_retarget``, rotations and translation copied, betas swapped;
    "source": ``source_score`` of the dataset clips, absent if there are none) over every clip of
    ``clips`` (dataset clip ids or mocap files) moved onto every body of ``target_betas_list``
    ((10,) betas each). ``checkpoint``: SA-VAE run folder or .pt. progress(fraction, clip).
    The SA-VAE side is decoded as ``generation.retarget.retarget`` does (the source's contacts
    planted unless ``plant_source_contacts`` is False: the decoder's own contacts; the codes searched
    for on the subject's body unless ``search`` is False: the encoders' codes). "auto" is what the
    product's Retarget gives: the SA-VAE's motion, or for a clip whose codes miss it by more than
    ``fallback_mm`` (default ``take_fidelity.LOST_TAKE_MM``) in its worst second the take's own
    rotations with its feet planted (``retarget.planted_retarget``); its "fallbacks" counts those clips."""
    from ..generation.retarget import (check_betas, decode_tokens, encode_take, ground_each_frame, load_vae,
                                       naive_retarget, planted_retarget, processor, source_joints, swap_betas_retarget)
    from ..generation.take_fidelity import LOST_TAKE_MM, worst_take_error_mm
    from ..io.mocap import Motion22
    from .recon import _body

    fallback_mm = LOST_TAKE_MM if fallback_mm is None else float(fallback_mm)

    clips, targets = list(clips), [check_betas(b) for b in target_betas_list]
    if not clips or not targets:
        raise ShapeMoveError("compare_retargeting needs at least one clip and one target body")
    body = _body(body)
    vae = load_vae(checkpoint, body)
    rows = {"savae": [], "auto": [], "naive": [], "naive_frame": [], "swap": [], "source": []}
    fallbacks = 0
    for i, clip in enumerate(clips):
        joints, name = source_joints(source_motion(data, clip), body)
        src = Motion22(joints=joints, fps=float(FPS), source=name, subject="", offsets=np.zeros((22, 3)))  # read once
        arrays = processor(body, ik_refine_iters).process(joints)
        codes = encode_take(vae, arrays["norm_joint_vecs"], arrays["betas"], arrays["new_joint_vecs"], search)
        lost = worst_take_error_mm(codes, vae, arrays["betas"], arrays["new_joint_vecs"]) > fallback_mm
        fallbacks += lost
        known = arrays["contacts"]   # source_contacts of the joints; also where the slide of planted feet is measured
        contacts = known if plant_source_contacts else None
        for betas in targets:
            savae = _score(body, decode_tokens(codes, vae, body, betas, ik_refine_iters, contacts=contacts), betas, known)
            rows["savae"].append(savae)
            rows["auto"].append(_score(body, planted_retarget(arrays, body, betas, ik_refine_iters), betas, known)
                                if lost else savae)
            naive = naive_retarget(src, body, betas, ik_refine_iters)
            rows["naive"].append(_score(body, naive, betas, known))
            rows["naive_frame"].append(_score(body, ground_each_frame(naive, body), betas, known))
            rows["swap"].append(_score(body, swap_betas_retarget(src, body, betas, ik_refine_iters), betas, known))
        if isinstance(clip, str) and (src_row := source_score(body, data, clip)) is not None:
            rows["source"].append(src_row)
        if progress is not None:
            progress((i + 1) / len(clips), str(clip))
    out = {}
    for name, r in rows.items():
        if not r:
            continue
        agg = aggregate(r)
        n = sum(row["n_stance"] for row in r)
        for k in STANCE_KEYS:   # pooled over the planted joint-pairs, not the frames
            agg[k] = sum(row[k] * row["n_stance"] for row in r) / n if n else 0.0
        out[name] = {**{k: float(agg[k]) for k in KEYS}, "clips": len(r) if name == "source" else len(clips),
                     "bodies": 1 if name == "source" else len(targets)}
    out["auto"]["fallbacks"] = int(fallbacks)
    return out
