"""SA-VAE reconstruction quality on a built dataset split, beside the ground truth.

For each clip: the canonical features (``norm_joint_vecs``) are normalized, encoded to tokens (by
default searched for against the clip's own shape-aware motion, ``code_search``, as a retargeted
take is encoded; ``search=False``: the encoders' codes) and decoded with the clip's own betas
(``decode_long``, as generation does) -> shape-aware features -> joints (``joints_from_features``;
NOT re-grounded, so the model's floor errors count) -> IK onto the body with those betas -> mesh
metrics (``evaluate_motion``; bone metrics on the decoded joints). MPJPE is against the
ground-truth shape-aware joints recovered from ``new_joint_vecs`` (same canonical frame, same
frames); ``mpjpe_local_mm`` is the same with both motions' roots aligned per frame (the pose error
without the drift of the integrated root trajectory). The ground truth column is the dataset's
shape-aware motion itself: ``poses``/``transl`` on the body with the clip's betas (its MPJPE is 0
by definition).
Frames: the (T-1) feature rows cut to a multiple of the VAE's downsampling.

Result (also the JSON of ``eval recon``)::

    {"mpjpe_mm", "mpjpe_local_mm", "bone_err_mm", "penetrate_cm", "float_cm", "skate_pct", "dyn_stable_pct",
     "code_usage_pct", "clips",                       # the reconstruction
     "ground_truth": {same keys; code_usage_pct None}}

Metrics are frame-weighted over all clips (``report.aggregate``); code usage is the share of the
codebook used by all tokens of the split.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from ..body.ik import solve_ik
from ..body.load import load_body_model
from ..errors import ShapeMoveError
from ..generation.retarget import encode_take, load_vae
from ..geometry.rotations import axis_angle_to_matrix
from ..models.fsq import codebook_usage
from ..models.motion_codes import base_of
from ..motion.features import joints_from_features
from ..train.motion_dataset import read_split
from .bones import mpjpe_mm
from .evaluate import evaluate_motion
from .report import aggregate

KEYS = ("mpjpe_mm", "mpjpe_local_mm", "bone_err_mm", "penetrate_cm", "float_cm", "skate_pct", "dyn_stable_pct",
        "penetrate_all_cm", "float_all_cm", "skate_joints_pct")  # *_all_cm: the paper's (mean over all frames)


def _body(body):
    if body is not None and not isinstance(body, str):
        return body

    return load_body_model(body)


def _load(root: Path, sub: str, cid: str) -> np.ndarray:
    p = root / sub / f"{cid}.npy"
    try:
        return np.load(p).astype(np.float32)
    except FileNotFoundError:
        raise ShapeMoveError(f"{root}: clip '{cid}' has no {sub}/ file; is this a dataset from `data build`?") from None


def _pick(agg: dict) -> dict:
    return {k: float(agg[k]) for k in KEYS}


def recon_clip(vae, body, norm_feats: np.ndarray, betas: np.ndarray, ik_refine_iters: int = 10,
               base_only: bool = False, shaped_feats: np.ndarray | None = None):
    """(T-1,263) canonical features + betas -> (joints (n,22,3), rotations (n,24,3,3), transl (n,3),
    base token indices (n/4,)) of the reconstruction, n = (T-1) cut to a multiple of the
    downsampling. A codec with a residual code decodes both codes unless ``base_only`` (what the
    T5, which writes base codes, can reach: the base encoder's codes). With ``shaped_feats`` (the
    clip's shape-aware features) the codes are searched for, as retargeting encodes a take
    (``generation.retarget.encode_take``); else they are the encoders'."""
    n = len(norm_feats) // vae.cfg.downsample * vae.cfg.downsample
    if n == 0:
        raise ShapeMoveError(f"clip too short for the SA-VAE ({len(norm_feats)} feature rows)")
    b = torch.as_tensor(betas, dtype=torch.float32).reshape(1, 10)
    if base_only:
        with torch.no_grad():
            tokens = vae.encode(vae.normalize(torch.as_tensor(norm_feats[:n]))[None])[1]
    else:
        tokens = torch.as_tensor(encode_take(vae, norm_feats, b[0], shaped_feats))[None]
    with torch.no_grad():  # (not around the IK: its refinement takes gradients)
        indices = base_of(tokens, vae.quantizer.codebook_size)
        feats = vae.denormalize(vae.decode_tokens_long(tokens, b))[0]
        joints = joints_from_features(feats.double()).float().numpy()
    ik = solve_ik(joints, body.rest_joints(b)[0].numpy(), refine_iters=ik_refine_iters)
    return joints, ik.rotations, ik.transl, indices[0]


def eval_recon(data, checkpoint, split: str = "test", body=None, max_clips: int | None = None, progress=None,
               ik_refine_iters: int = 10, per_clip: list | None = None, base_only: bool = False,
               search: bool = True) -> dict:
    """Reconstruction metrics of the SA-VAE ``checkpoint`` (run folder or .pt) on the ``split``
    clips of the dataset folder ``data``, with the ground truth's beside (see the module doc).
    progress(fraction, clip id) after each clip; ``per_clip``: a list to receive one dict per clip
    ({"id", "frames", the KEYS, "ground_truth": {KEYS}}); ``base_only``: a residual codec decodes
    its base codes alone (``recon_clip``); ``search``: the codes are searched for against the
    clip's shape-aware joints, as retargeting encodes a take (``code_search``), else the encoders'
    codes (never with ``base_only``)."""
    root = Path(data)
    if not root.is_dir():
        raise ShapeMoveError(f"dataset folder not found: {root}")
    if split not in ("train", "val", "test"):
        raise ShapeMoveError(f"split must be train, val or test, got {split!r}")
    body = _body(body)
    vae = load_vae(checkpoint, body)
    ids = read_split(root, split)
    if max_clips and len(ids) > max_clips:  # a seeded random subset: the split is sorted by source
        ids = [ids[i] for i in np.sort(np.random.default_rng(0).choice(len(ids), max_clips, replace=False))]
    if not ids:
        raise ShapeMoveError(f"{root}: the {split} split has no clips ({split}.txt missing or empty)")
    model_rows, gt_rows, all_indices = [], [], []
    for i, cid in enumerate(ids):
        betas = _load(root, "betas", cid).reshape(-1)
        shaped = _load(root, "new_joint_vecs", cid)
        joints, rot, transl, idx = recon_clip(vae, body, _load(root, "norm_joint_vecs", cid), betas, ik_refine_iters,
                                              base_only, shaped if search else None)
        n = len(joints)
        gt_joints = joints_from_features(shaped[:n].astype(np.float64))
        m = evaluate_motion(body, betas, rot, transl, joints=joints)
        m["mpjpe_mm"] = mpjpe_mm(joints, gt_joints)
        m["mpjpe_local_mm"] = mpjpe_mm(joints, gt_joints, root_aligned=True)  # pose only, no trajectory drift
        gt_rot = axis_angle_to_matrix(_load(root, "poses", cid)[:n])
        g = evaluate_motion(body, betas, gt_rot, _load(root, "transl", cid)[:n])
        g["mpjpe_mm"] = g["mpjpe_local_mm"] = mpjpe_mm(gt_joints, gt_joints)
        if per_clip is not None:
            per_clip.append({"id": cid, "frames": n, **_pick(m), "ground_truth": _pick(g)})
        model_rows.append(m)
        gt_rows.append(g)
        all_indices.append(idx)
        if progress is not None:
            progress((i + 1) / len(ids), cid)
    usage = codebook_usage(torch.cat(all_indices), vae.quantizer.codebook_size)["used_fraction"] * 100.0
    return {**_pick(aggregate(model_rows)), "code_usage_pct": float(usage), "clips": len(ids),
            "ground_truth": {**_pick(aggregate(gt_rows)), "code_usage_pct": None, "clips": len(ids)}}
