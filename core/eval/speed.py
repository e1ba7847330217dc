"""Does the motion codec keep locomotion's speed? (issue #24) The check behind `eval speed`.

(a) Real clips: every clip of the split whose main action (``labels.actions[0]`` in its meta) is
    walk, jog, run or sprint is encoded (its canonical features, ``norm_joint_vecs``; the codes
    searched for on its own body, ``generation.retarget.encode_take``, unless ``search`` is False)
    and decoded on the clip's own betas (as ``eval recon`` and retargeting do). Its root speed is compared with
    the clip's own shape-aware motion (``new_joint_vecs``, same body, same frames) two ways:
    ``decoded``: the root of the decoded features (``joints_from_features``), what the codec
    carries; ``final``: the root of the Motion the user gets (``generation.decode.decode_tokens``:
    the decoder's contacts planted, IK onto the body, grounded on the soles). Per action: mean
    speeds, their ratio (total decoded distance / total original distance, i.e. frame-weighted;
    target ``TARGET`` = 0.95), the mean of the per-clip ratios, and the per-frame correlation of
    the root's horizontal velocity (``gait.velocity_correlation``, frame-weighted mean over clips),
    and the legs' swing ratio (``gait.swing``, decoded / original: < 1 when the legs step short,
    which no root fix can give back).
    ``feet=True`` adds the fallback of ``motion.root_from_feet`` (the root's travel re-derived
    from the decoded feet planted by the decoder's contacts): ``feet`` (decoded joints moved) and
    ``feet_final`` (those joints planted and IK'd, ``generation.decode.motion_from_joints``).
(b) Generated locomotion (``model_dir``): for each action, ``PROMPTS`` (several phrasings) x
    ``seeds`` are generated on the betas of that action's real clips (round robin, so the bodies
    match); the mean root speed of the generated motions (decoded features' root and the final
    Motion's) over the mean speed of the real clips of that action.
(c) Shape conditioning (``shape_clips`` walk clips): the same tokens decoded on a short and a tall
    OpenBody (phenotype height at its slider's ends, ``shape_bodies``): stride length should grow
    with leg length (ratio near the leg-length ratio, ``gait.leg_length``) and cadence stay put
    (ratio within 5 %), on the decoded features and on the final Motion.

Result: see ``speed_check``; written by `python -m shapemove eval speed` as JSON.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from ..body.load import load_body_model
from ..body.plant import contacts_from_features
from ..data.built_meta import read_meta
from ..errors import ShapeMoveError
from ..generation.decode import decode_features, decode_tokens, motion_from_joints
from ..generation.retarget import encode_take, load_vae
from ..motion.features import joints_from_features
from ..motion.root_from_feet import root_from_feet
from ..train.motion_dataset import read_split
from .gait import cadence, leg_length, mean_speed, min_cycle_frames, stride_length, swing, velocity_correlation

LOCOMOTION = ("walk", "jog", "run", "sprint")
TARGET = 0.95          # decoded / original mean root speed (issue #24)
CADENCE_TOL = 0.05     # short vs tall body: cadence ratio within 1 +- this
PROMPTS = {
    "walk": ["a person walks forward", "someone walks straight ahead", "a man is walking at a normal pace",
             "a woman takes a walk"],
    "jog": ["a person jogs forward", "someone jogs straight ahead", "a man is jogging", "a woman goes for a jog"],
    "run": ["a person runs forward", "someone runs straight ahead", "a man is running", "a woman runs fast"],
    "sprint": ["a person sprints forward", "someone dashes forward at full speed", "a man is sprinting",
               "a woman sprints as fast as she can"],
}
SHAPE_HEIGHTS = {"short": 0.0, "tall": 1.0}   # position on the OpenBody height slider's range


def _load(root: Path, sub: str, cid: str) -> np.ndarray:
    p = root / sub / f"{cid}.npy"
    if not p.is_file():
        raise ShapeMoveError(f"{root}: clip '{cid}' has no {sub}/ file; is this a dataset from `data build`?")
    return np.load(p, allow_pickle=False).astype(np.float32)


def locomotion_clips(data, split: str = "test", actions=LOCOMOTION) -> dict[str, list[str]]:
    """{action: clip ids} of the ``split`` whose main action (``labels.actions[0]``) is one of
    ``actions`` (each action listed, possibly with no clips)."""
    root = Path(data)
    if not root.is_dir():
        raise ShapeMoveError(f"dataset folder not found: {root}")
    if split not in ("train", "val", "test"):
        raise ShapeMoveError(f"split must be train, val or test, got {split!r}")
    ids = read_split(root, split)
    if not ids:
        raise ShapeMoveError(f"{root}: the {split} split has no clips ({split}.txt missing or empty; "
                             "is the dataset build finished?)")
    out: dict[str, list[str]] = {a: [] for a in actions}
    for cid, meta in read_meta(root, ids).items():
        acts = (meta.get("labels") or {}).get("actions") or []
        if acts and acts[0] in out:
            out[acts[0]].append(cid)
    return out


def _decoded_joints(codes, vae, betas) -> tuple[np.ndarray, np.ndarray]:
    feats = decode_features(codes, vae, betas).double()
    with torch.no_grad():
        return joints_from_features(feats).numpy(), feats.numpy()


def clip_speeds(vae, body, norm_feats, shape_feats, betas, feet: bool = False, ik_refine_iters: int = 10,
                search: bool = True) -> dict:
    """One real clip through the codec on its own betas -> {"frames", "orig_mps", and for each of
    "decoded", "final" (and with ``feet`` "feet", "feet_final"): "<kind>_mps", "<kind>_corr",
    "<kind>_swing_m"} (``gait.swing``: how far the feet reach apart; "orig_swing_m" the clip's).
    ``search``: encoded as a retargeted take is (``encode_take``), else by the encoders alone."""
    codes = encode_take(vae, norm_feats, betas, shape_feats, search)
    joints, feats = _decoded_joints(codes, vae, betas)
    n = len(joints)
    orig = joints_from_features(np.asarray(shape_feats[:n], np.float64))
    motions = {"decoded": joints, "final": decode_tokens(codes, vae, body, betas, ik_refine_iters).joints}
    if feet:
        contacts = contacts_from_features(feats)
        moved = root_from_feet(joints, contacts)
        motions["feet"] = moved
        motions["feet_final"] = motion_from_joints(body, betas, moved.astype(np.float32), contacts,
                                                   ik_refine_iters).joints
    out = {"frames": n, "orig_mps": mean_speed(orig), "orig_swing_m": swing(orig)}
    for kind, j in motions.items():
        out[f"{kind}_mps"] = mean_speed(j)
        out[f"{kind}_corr"] = velocity_correlation(j, orig)
        out[f"{kind}_swing_m"] = swing(j)
    return out


def _summary(rows: list[dict], kinds) -> dict:
    """Per-clip rows -> frame-weighted speeds, their ratios, the mean per-clip ratio, correlations."""
    w = np.array([r["frames"] - 1 for r in rows], np.float64)
    mean = lambda key: float((w * np.array([r[key] for r in rows])).sum() / w.sum())  # noqa: E731
    out = {"clips": len(rows), "frames": int(sum(r["frames"] for r in rows)), "orig_mps": mean("orig_mps"),
           "orig_swing_m": mean("orig_swing_m")}
    for k in kinds:
        out[f"{k}_swing_ratio"] = mean(f"{k}_swing_m") / out["orig_swing_m"]
        out[f"{k}_mps"] = mean(f"{k}_mps")
        out[f"{k}_ratio"] = out[f"{k}_mps"] / out["orig_mps"]
        out[f"{k}_ratio_clip_mean"] = float(np.mean([r[f"{k}_mps"] / r["orig_mps"] for r in rows]))
        corr = np.array([r[f"{k}_corr"] for r in rows])
        ok = np.isfinite(corr)
        out[f"{k}_corr"] = float((w[ok] * corr[ok]).sum() / w[ok].sum()) if ok.any() else float("nan")
    return out


def shape_bodies(body) -> dict[str, np.ndarray]:
    """{"short", "tall"}: OpenBody betas at the ends of the height slider, the other sliders at
    their defaults."""
    if not hasattr(body, "betas_from_phenotype"):
        raise ShapeMoveError("the shape check needs OpenBody's phenotype sliders (the default body model)")
    names = list(body.phenotype_names)
    if "height" not in names:
        raise ShapeMoveError(f"this OpenBody has no height slider (sliders: {', '.join(names)})")
    lo, hi = body.phenotype_ranges[names.index("height")]
    out = {}
    for name, at in SHAPE_HEIGHTS.items():
        ph = dict(zip(names, body.phenotype_defaults))
        ph["height"] = float(lo + at * (hi - lo))
        out[name] = body.betas_from_phenotype(ph)
    return out


def shape_gait(codes, vae, body, bodies: dict, ik_refine_iters: int = 10) -> dict:
    """The same tokens on the ``bodies`` {"short", "tall"} -> {"leg_ratio", and for "decoded" and
    "final": "<kind>_stride_ratio", "<kind>_cadence_ratio", "<kind>_speed_ratio" (tall / short),
    "<kind>_cadence_short", "<kind>_stride_short_m", "<kind>_stride_tall_m"}."""
    legs = {k: leg_length(body, b) for k, b in bodies.items()}
    joints = {}
    for k, b in bodies.items():
        joints[("decoded", k)] = _decoded_joints(codes, vae, b)[0]
        joints[("final", k)] = decode_tokens(codes, vae, body, b, ik_refine_iters).joints
    out = {"leg_short_m": legs["short"], "leg_tall_m": legs["tall"], "leg_ratio": legs["tall"] / legs["short"]}
    for kind in ("decoded", "final"):
        s, t = joints[(kind, "short")], joints[(kind, "tall")]
        out[f"{kind}_stride_short_m"], out[f"{kind}_stride_tall_m"] = stride_length(s), stride_length(t)
        out[f"{kind}_stride_ratio"] = out[f"{kind}_stride_tall_m"] / out[f"{kind}_stride_short_m"]
        out[f"{kind}_cadence_short"] = cadence(s)
        out[f"{kind}_cadence_ratio"] = cadence(t) / out[f"{kind}_cadence_short"]
        out[f"{kind}_speed_ratio"] = mean_speed(t) / mean_speed(s)
    return out


def generated_speeds(model_dir, body, real: dict[str, dict], real_betas: dict[str, list], seeds=(0, 1),
                     prompts=PROMPTS, progress=None) -> dict:
    """Generated locomotion against the real clips: ``real`` {action: summary with "orig_mps"},
    ``real_betas`` {action: [betas of its real clips]} -> {action: {"samples", "real_mps",
    "decoded_mps", "final_mps", "decoded_ratio", "final_ratio", "per_prompt": {prompt: final_mps}}}."""
    from ..generation.generate import Generator, Request

    gen = Generator(model_dir, body=body)
    acts = [a for a in prompts if real.get(a, {}).get("clips")]
    total, done, out = sum(len(prompts[a]) * len(seeds) for a in acts), 0, {}
    for a in acts:
        dec, fin, per_prompt, i = [], [], {}, 0
        for p in prompts[a]:
            for s in seeds:
                betas = real_betas[a][i % len(real_betas[a])]
                i += 1
                m = gen.generate_batch([Request(p, betas=betas, seed=int(s))])[0]
                dec.append(mean_speed(joints_from_features(np.asarray(m.features, np.float64))))
                fin.append(mean_speed(m.joints))
                per_prompt.setdefault(p, []).append(fin[-1])
                done += 1
                if progress is not None:
                    progress(done / total, f"{a}: {p}")
        r = real[a]["orig_mps"]
        out[a] = {"samples": len(dec), "real_mps": r, "decoded_mps": float(np.mean(dec)), "final_mps": float(np.mean(fin)),
                  "decoded_ratio": float(np.mean(dec)) / r, "final_ratio": float(np.mean(fin)) / r,
                  "per_prompt": {p: float(np.mean(v)) for p, v in per_prompt.items()}}
    return out


def speed_check(data, checkpoint, split: str = "test", model_dir=None, feet: bool = False, max_clips: int | None = None,
                shape_clips: int = 8, seeds=(0, 1), body=None, ik_refine_iters: int = 10, progress=None,
                search: bool = True) -> dict:
    """The whole check (module doc). ``max_clips``: at most that many clips per action (a seeded
    random subset); ``shape_clips``: walk clips for the shape check (0: none); ``search``: real
    clips are encoded as a retargeted take is (codes searched for on the clip's own body), else by
    the encoders alone. Returns::

        {"checkpoint", "split", "target": 0.95, "kinds": [...],
         "actions": {action: summary}, "all": summary over every clip,
         "shape": {"bodies": {...}, "clips", "leg_ratio", "decoded_stride_ratio", ... (means)},
         "generated": {action: {...}} (only with model_dir),
         "per_clip": [{"id", "action", "frames", "orig_mps", "<kind>_mps", "<kind>_corr"}]}
    """
    root = Path(data)
    if max_clips is not None and max_clips < 1:
        raise ShapeMoveError("--max-clips must be at least 1")
    if shape_clips < 0:
        raise ShapeMoveError("--shape-clips must be 0 or more")
    by_action = locomotion_clips(root, split)   # a wrong folder or split is refused before any model loads
    body = body if body is not None and not isinstance(body, str) else load_body_model(body)
    vae = load_vae(checkpoint, body)
    rng = np.random.default_rng(0)
    for a, ids in by_action.items():
        if max_clips and len(ids) > max_clips:
            by_action[a] = [ids[i] for i in np.sort(rng.choice(len(ids), max_clips, replace=False))]
    if not any(by_action.values()):
        raise ShapeMoveError(f"{root}: the {split} split has no walk, jog, run or sprint clips (labels.actions[0])")
    kinds = ["decoded", "final"] + (["feet", "feet_final"] if feet else [])
    need = min_cycle_frames() + vae.cfg.downsample  # decoded frames the gait cycle needs, after the cut to 4
    walks = [c for c in by_action.get("walk", []) if len(np.load(root / "norm_joint_vecs" / f"{c}.npy",
                                                                 mmap_mode="r")) >= need][:shape_clips]
    n_total = sum(map(len, by_action.values())) + len(walks)
    rows, done = [], 0
    for a, ids in by_action.items():
        for cid in ids:
            r = clip_speeds(vae, body, _load(root, "norm_joint_vecs", cid), _load(root, "new_joint_vecs", cid),
                            _load(root, "betas", cid).reshape(-1), feet, ik_refine_iters, search)
            rows.append({"id": cid, "action": a, **r})
            done += 1
            if progress is not None:
                progress(done / n_total, cid)
    result = {"checkpoint": str(checkpoint), "split": split, "target": TARGET, "kinds": kinds,
              "actions": {a: _summary([r for r in rows if r["action"] == a], kinds)
                          for a in by_action if by_action[a]},
              "all": _summary(rows, kinds)}
    if walks:
        bodies = shape_bodies(body)
        per = []
        for cid in walks:
            codes = encode_take(vae, _load(root, "norm_joint_vecs", cid), _load(root, "betas", cid).reshape(-1),
                                _load(root, "new_joint_vecs", cid), search)
            per.append(shape_gait(codes, vae, body, bodies, ik_refine_iters))
            done += 1
            if progress is not None:
                progress(done / n_total, f"shape {cid}")
        result["shape"] = {"clips": walks, "cadence_tol": CADENCE_TOL,
                           **{k: float(np.mean([p[k] for p in per])) for k in per[0]}}
    if model_dir is not None:
        betas = {a: [_load(root, "betas", c).reshape(-1) for c in ids] for a, ids in by_action.items() if ids}
        result["generated"] = generated_speeds(model_dir, body, result["actions"], betas, seeds, progress=progress)
    result["per_clip"] = rows
    return result
