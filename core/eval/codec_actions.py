"""Does the codec keep the action? ``eval codec-actions``.

Captured clips of each action are encoded and decoded by an SA-VAE, and the decoded motion is
judged as ``eval paraphrase`` judges a generated one: the action of its 5 nearest training clips,
by TMA embedding and by raw features, the clip's own take left out (``action_classifier.py``).
For each action (up to ``per_action`` captured clips, not mirrors, shape-augmented copies or
compositions; drawn with seed 0) the report gives how many the judge reads right from the
capture, and of those how many it still reads right decoded from the base codes (what the T5
writes and the generator plays) and from both codes (a residual codec). A motion the base codes
cannot carry, no prompt can ask for: this is the ceiling the codec puts on each action.

Beside the judges, the extremities (``extremities``): peak foot and hand height above the floor
and the hands' and feet's reach from the pelvis, in the capture and in each decoding, so a kick
decoded as standing shows as a foot that no longer rises.

    python -m shapemove eval codec-actions --checkpoint weights/default/savae.pt --data data/built \\
        --split test --json out/codec_actions.json
"""
from __future__ import annotations

import random
from pathlib import Path

import numpy as np

FEET, HANDS = (7, 8, 10, 11), (20, 21)


def captured_clips(data: Path, split: str, actions: list[str], per_action: int, seed: int = 0) -> list[tuple[str, str]]:
    """(action, clip id): up to ``per_action`` captured clips of each action (their main label),
    drawn with ``seed``; mirror images, shape-augmented copies and compositions left out."""
    from ..data.built_meta import read_meta
    from .action_classifier import clip_actions

    path = Path(data) / f"{split}.txt"
    ids = [i for i in path.read_text(encoding="utf-8").split() if i] if path.is_file() else []
    metas = read_meta(data, ids)
    ids = [i for i in ids if isinstance(metas.get(i), dict) and not metas[i].get("augmented_from")]
    labels = clip_actions(data, ids)   # [] for mirrors and compositions
    by: dict[str, list[str]] = {a: [] for a in actions}
    for i in ids:
        main = (labels.get(i) or [None])[0]
        if main in by:
            by[main].append(i)
    rng = random.Random(seed)
    return [(a, c) for a in actions for c in rng.sample(by[a], min(per_action, len(by[a])))]


def extremities(features: np.ndarray) -> dict:
    """Peak heights (m above the floor: the clip's lowest joint) of the feet and hands and their
    peak horizontal reach from the pelvis, of (T,263) shape-aware features."""
    import torch

    from ..motion.features import joints_from_features

    j = joints_from_features(torch.as_tensor(np.asarray(features, np.float32))).numpy()
    floor = j[..., 1].min()
    reach = lambda ids: float(np.linalg.norm(j[:, ids][..., [0, 2]] - j[:, None, 0, [0, 2]], axis=-1).max())  # noqa: E731
    return {"foot_height": float(j[:, FEET, 1].max() - floor), "hand_height": float(j[:, HANDS, 1].max() - floor),
            "foot_reach": reach(list(FEET)), "hand_reach": reach(list(HANDS))}


def codec_actions(checkpoint, data, split: str = "test", per_action: int = 6, model=None, search: bool = False,
                  progress: bool = True) -> dict:
    """The report: ``rows`` (one per clip: the judges' readings and the extremities of the capture
    and each decoding), ``per_action`` and ``all`` (counts of clips read right, by judge and way),
    ``extremity_ratio`` (per action: the decodings' mean peak / the captures')."""
    import torch
    from tqdm import tqdm

    from ..generation.decode import decode_features
    from ..generation.model_bundle import model_files, resolve_model_dir
    from ..generation.retarget import encode_take
    from ..generation.take_fidelity import take_error_mm, worst_second_mm
    from ..models.known_texts import read_known
    from ..models.motion_codes import base_of
    from ..models.savae import load_savae
    from ..torch_threads import one_torch_thread
    from .action_classifier import ActionClassifier
    from .tma_embed import load_tma

    data = Path(data)
    model_dir = resolve_model_dir(model)
    tma = load_tma(model_files(model_dir)["tma"])
    actions = read_known(model_dir / "t5").action_names
    vae = load_savae(checkpoint)
    judges = {"tma": ActionClassifier.from_data(tma, data, actions, progress=False),
              "raw": ActionClassifier.from_features(data, actions, progress=False)}
    ways = ["base"] + (["both"] if vae.has_residual else [])
    rows = []
    with one_torch_thread():
        for action, cid in tqdm(captured_clips(data, split, actions, per_action), desc="clips", unit="clip",
                                disable=not progress):
            canon = np.load(data / "norm_joint_vecs" / f"{cid}.npy")
            n = len(canon) // vae.cfg.downsample * vae.cfg.downsample
            if n < 4 * vae.cfg.downsample:
                continue
            shaped = np.load(data / "new_joint_vecs" / f"{cid}.npy")[:n]
            betas = np.load(data / "betas" / f"{cid}.npy").astype(np.float32)
            with torch.no_grad():
                tokens = encode_take(vae, canon, betas, shaped, search=True) if search else encode_take(vae, canon, search=False)
                feats = [shaped] + [decode_features(base_of(tokens, vae.quantizer.codebook_size) if w == "base"
                                                    else tokens, vae, betas).numpy() for w in ways]
                err = take_error_mm(tokens, vae, betas, shaped)
            row = {"clip": cid, "action": action, "error_mm": float(err.mean()), "worst_second_mm": worst_second_mm(err),
                   "extremities": dict(zip(["capture"] + ways, (extremities(f) for f in feats)))}
            for name, judge in judges.items():
                row[name] = dict(zip(["capture"] + ways, judge.classify(feats, exclude=[[cid]] * len(feats))))
            rows.append(row)
    per: dict[str, dict] = {}
    for r in rows:
        d = per.setdefault(r["action"], {"clips": 0, **{f"{j}_{w}": 0 for j in judges for w in ["capture"] + ways}})
        d["clips"] += 1
        for j in judges:
            if r[j]["capture"] == r["action"]:
                for w in ["capture"] + ways:
                    d[f"{j}_{w}"] += r[j][w] == r["action"]
    total = {k: sum(d[k] for d in per.values()) for k in next(iter(per.values()), {})}
    ratio = {}
    for a in per:
        mine = [r["extremities"] for r in rows if r["action"] == a]
        ratio[a] = {w: {k: float(np.mean([m[w][k] for m in mine]) / max(np.mean([m["capture"][k] for m in mine]), 1e-6))
                        for k in mine[0]["capture"]} for w in ways}
    return {"checkpoint": str(checkpoint), "split": split, "ways": ways, "judges": list(judges),
            "per_action": per, "all": total, "extremity_ratio": ratio, "rows": rows}


def table(report: dict) -> str:
    """The report as the command prints it: per action, clips read right by each judge from the
    capture and each decoding, then the decodings' peak foot height and hand reach against the capture's."""
    ways, judges = report["ways"], report["judges"]
    lines = ["action".ljust(22) + "clips" + "".join(f"  {j}: capture " + " ".join(ways) for j in judges)
             + "  foot height / hand reach (x capture)"]
    for act, d in list(report["per_action"].items()) + [("all", report["all"])]:
        ext = report["extremity_ratio"].get(act)
        tail = "" if ext is None else "  " + "  ".join(f"{w} {ext[w]['foot_height']:.2f}/{ext[w]['hand_reach']:.2f}"
                                                       for w in ways)
        lines.append(act.ljust(22) + f"{d['clips']:5d}" + "".join(
            f"  {j}: {d[f'{j}_capture']:7d} " + " ".join(f"{d[f'{j}_{w}']:{len(w)}d}" for w in ways) for j in judges)
            + tail)
    lines.append("counts: clips whose capture the judge reads right, then of those the ones each decoding keeps")
    return "\n".join(lines)


def add_arguments(p) -> None:
    p.add_argument("--checkpoint", type=Path, required=True, help="the SA-VAE (savae.pt) to check")
    p.add_argument("--data", type=Path, required=True, help="a built dataset (clips and the judges' references)")
    p.add_argument("--model", type=Path, default=None, help="model folder whose TMA judges (default weights/default)")
    p.add_argument("--split", default="test", help="clips to encode (default test)")
    p.add_argument("--per-action", type=int, default=6)
    p.add_argument("--search", action="store_true", help="the codes retargeting uses: searched on the clip's body")
    p.add_argument("--json", type=Path, default=None)


def from_cli(args) -> dict:
    report = codec_actions(args.checkpoint, args.data, args.split, args.per_action, args.model, args.search)
    print(table(report))
    if args.json:
        from ..atomic import atomic_write_json

        atomic_write_json(args.json, report)
    return report
