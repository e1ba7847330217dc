"""Check a built dataset's ground contact without the project's metric code: pose the body model with
each clip's stored (betas, poses, transl), take the lowest mesh vertex per frame and compute, by hand,
penetrate and float (the paper's definitions: mean over all frames of the depth below / height above
y = 0), the share of frames more than 5 mm under the floor, and how far the stored ``new_joints`` are
from the posed body's joints.

    python tools/check_built_ground.py data/built [--clips 40] [--split test] [--seed 0]
"""
from __future__ import annotations

import argparse
import random
import sys
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT.parent))
from shapemove.core.body.load import load_body_model  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("data", type=Path)
    ap.add_argument("--clips", type=int, default=40)
    ap.add_argument("--split", default="test")
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    split = a.data / f"{a.split}.txt"
    if not split.is_file():
        raise SystemExit(f"{a.data}: no {split.name} (not a built dataset?)")
    ids = split.read_text().split()
    random.Random(a.seed).shuffle(ids)
    ids = ids[:a.clips]
    torch.set_num_threads(1)
    body = load_body_model(None)
    lows, fk_err = [], 0.0
    for cid in ids:
        load = lambda sub: np.load(a.data / sub / f"{cid}.npy", allow_pickle=False)  # noqa: E731
        betas, poses, transl = load("betas").astype(np.float32).reshape(-1), load("poses"), load("transl")
        with torch.no_grad():
            out = body.forward(torch.as_tensor(betas)[None], torch.as_tensor(poses, dtype=torch.float32).reshape(len(poses), -1, 3),
                               torch.as_tensor(transl, dtype=torch.float32))
        lows.append(out.vertices[..., 1].min(-1).values.numpy())
        fk_err = max(fk_err, float(np.abs(out.joints[:, :22].numpy() - load("new_joints")).max()))
    low = np.concatenate(lows)
    print(f"{a.data}: {len(ids)} {a.split} clips, {len(low)} frames; penetrate {np.maximum(-low, 0).mean() * 100:.3f} cm, "
          f"float {np.maximum(low, 0).mean() * 100:.3f} cm, frames > 5 mm under {np.mean(low < -0.005) * 100:.1f} %, "
          f"stored joints vs posed body {fk_err * 1000:.2f} mm")


if __name__ == "__main__":
    main()
