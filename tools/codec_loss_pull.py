"""Which SA-VAE losses pull a captured motion's raised foot down: each loss term measured on the
captures themselves, per action.

A decoder trained to minimise a term that is not zero on real motion is pulled away from real
motion. For every clip of the chosen actions this evaluates each physical term of ``vae_losses``
with the prediction equal to the capture (what a perfect codec would pay), then takes one
normalised gradient step of that term alone on the capture's features and measures how the
clip's highest ankle peak moves (mm; negative: the term pushes the raised foot down).

    python tools/codec_loss_pull.py --data data/built --actions kick walk punch squat --json out/loss_pull.json
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT.parent))

TERMS = ("vel", "bone", "floating", "slide", "penetrate", "dyn_stability", "root")
STEP = 0.05     # size of the gradient step in normalised feature units (per-frame RMS)


def clip_pull(data: Path, cid: str, body, mean, std) -> dict:
    from shapemove.core.models.savae import LossWeights
    from shapemove.core.models.vae_losses import vae_losses
    from shapemove.core.motion.features import joints_from_features
    from shapemove.core.train.motion_dataset import CONTACT_ORDER
    from shapemove.core.train.train_vae import body_soles, target_bones

    f = np.load(data / "new_joint_vecs" / f"{cid}.npy").astype(np.float32)
    c = np.load(data / "contacts" / f"{cid}.npy")[:len(f)][:, CONTACT_ORDER].astype(np.float32)
    betas = torch.as_tensor(np.load(data / "betas" / f"{cid}.npy").astype(np.float32).reshape(1, 10))
    y = torch.as_tensor((f - mean) / std)[None]
    m, s = torch.as_tensor(mean), torch.as_tensor(std)
    with torch.no_grad():
        ankles = joints_from_features(y * s + m)[0, :, [7, 8], 1]
    peak = float(ankles.max())
    out = {}
    for term in TERMS:
        w = LossWeights(**{k: 0.0 for k in vars(LossWeights())})
        setattr(w, term, 1.0)
        pred = y.clone().requires_grad_(True)
        losses = vae_losses(pred, y, m, s, w, target_bones(body, betas), body_soles(body, betas), torch.as_tensor(c)[None])
        value = float(losses[term])
        grad, = torch.autograd.grad(losses["total"], pred, allow_unused=True)
        moved = 0.0
        if grad is not None and float(grad.norm()) > 0:
            rms = grad.pow(2).mean().sqrt()
            with torch.no_grad():
                stepped = joints_from_features((y - STEP * grad / rms) * s + m)[0, :, [7, 8], 1]
            moved = (float(stepped.max()) - peak) * 1000
        out[term] = {"value": value, "peak_moved_mm": moved}
    return {"peak_m": peak, "terms": out}


def main(argv=None) -> None:
    from shapemove.core.body.load import load_body_model
    from shapemove.core.data.actions import stored_labels
    from shapemove.core.models.savae import load_savae

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", type=Path, required=True)
    ap.add_argument("--actions", nargs="+", required=True)
    ap.add_argument("--max-clips", type=int, default=12, help="per action")
    ap.add_argument("--vae", type=Path, default=ROOT / "weights" / "default" / "savae.pt",
                    help="the normalisation (Mean/Std) of this codec")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args(argv)
    body = load_body_model(None)
    vae = load_savae(args.vae)
    mean, std = vae.mean.numpy(), vae.std.numpy()
    ids = sorted(p.stem for p in (args.data / "meta").glob("*.json") if not p.stem.endswith(("_aug", "_mirror")))
    report = {}
    for action in args.actions:
        mine = [c for c in ids if (stored_labels(args.data, c).get("actions") or [""])[0] == action][: args.max_clips]
        rows = [clip_pull(args.data, c, body, mean, std) for c in mine]
        if not rows:
            continue
        report[action] = {"clips": len(rows), "peak_m": float(np.mean([r["peak_m"] for r in rows])),
                          **{t: {k: float(np.mean([r["terms"][t][k] for r in rows])) for k in ("value", "peak_moved_mm")}
                             for t in TERMS}}
    print(f"{'action':14s} {'clips':>5s}  " + "  ".join(f"{t:>16s}" for t in TERMS))
    for a, r in report.items():
        print(f"{a:14s} {r['clips']:5d}  " + "  ".join(f"{r[t]['value']:7.4f} {r[t]['peak_moved_mm']:+7.1f}" for t in TERMS))
    print("(each term: its value on the capture, then the ankle peak moved by one step of it alone, mm)")
    if args.json:
        from shapemove.core.atomic import atomic_write_json
        atomic_write_json(args.json, report)


if __name__ == "__main__":
    main()
