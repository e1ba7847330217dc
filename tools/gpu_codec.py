"""Train the SA-VAE from scratch on a lent GPU machine, which holds no ShapeMove data, in three steps.

    python tools/gpu_codec.py pack --data data/built --out .gpu_codec                      # here
    python3 tools/gpu_codec.py train --pack .gpu_codec --config configs/default_codec.json \\
        --minutes 7 --out $OUT                                                             # there
    python tools/gpu_codec.py unpack --state $OUT --out runs/codec_gpu                     # here

Only 64 MiB travel to the GPU machine, the repository included, so ``pack`` keeps what the
features are made from, not the features (263 numbers a frame, twice): per captured take of the
training and validation splits its local rotations (22 joints, axis-angle, float16), its root
path, foot contacts and fitted betas, and its labels. There, ``train`` rebuilds a dataset folder
as ``data build`` writes one (``ClipProcessor.pose_on`` and ``features`` on the machine's cores):
every training take on its own body, mirrored, and on ``--bodies`` bodies sampled from the shape
space (``build._augment_body``), each also mirrored; the validation takes as captured. Then
``train_vae`` runs the config with every clip held on the GPU (``train.resident``) and its step
count fitted to ``--minutes``. The weights come back in float16 (under the 16 MiB a returned file
may hold) with the run's log; ``unpack`` writes a ``savae.pt`` here (``load_savae`` reads it).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT.parent))

PACK = "takes.npz"
CLIPS = "clips.json"
RAD = 1e-3    # rotation step of the pack (radians): under a millimetre at the hand
MM = 1e-3     # root step (metres)


def squeeze(a: np.ndarray, step: float, lengths: np.ndarray) -> np.ndarray:
    """(N, ...) float frames of clips of ``lengths`` -> lzma bytes (uint8) of their int16 steps of
    ``step`` from each frame to the next (a clip's first frame from zero), channel-major: a
    motion changes little from frame to frame, so this packs 3-4x tighter than float16."""
    import lzma

    q = np.round(np.asarray(a, np.float64).reshape(len(a), -1) / step).astype(np.int64)
    d = np.diff(q, axis=0, prepend=0)
    d[np.cumsum(lengths)[:-1]] = q[np.cumsum(lengths)[:-1]]     # every clip restarts from zero
    if np.abs(d).max() > 32767:
        raise ValueError("a step too large for int16")
    return np.frombuffer(lzma.compress(np.ascontiguousarray(d.astype(np.int16).T).tobytes(), preset=9), np.uint8)


def unsqueeze(b: np.ndarray, step: float, lengths: np.ndarray, shape: tuple) -> np.ndarray:
    """``squeeze``'s inverse: (N, *shape) float32, each value within ``step`` / 2 of the original."""
    import lzma

    n = int(np.sum(lengths))
    d = np.frombuffer(lzma.decompress(b.tobytes()), np.int16).reshape(-1, n).T.astype(np.int64)
    total = np.cumsum(d, axis=0)
    starts = np.cumsum(lengths) - lengths
    before = np.where(starts[:, None] > 0, total[np.maximum(starts - 1, 0)], 0)   # the sum before each clip
    q = total - np.repeat(before, lengths, axis=0)
    return (q * step).astype(np.float32).reshape(n, *shape)


def _originals(data: Path) -> list[dict]:
    """Meta of the built dataset's captured takes (no shape-augmented, mirrored or composed copy)
    of the training and validation splits."""
    metas = [json.loads(p.read_text()) for p in sorted((data / "meta").glob("*.json"))]
    return [m for m in metas if m.get("split") in ("train", "val") and not m.get("augmented_from")
            and not m.get("mirror_of") and not m.get("composed_from") and not m["id"].endswith("_mirror")
            and (data / "poses" / f"{m['id']}.npy").is_file()]


def pack(args) -> None:
    import torch

    from shapemove.core.atomic import atomic_path, atomic_write_json
    from shapemove.core.body.load import load_body_model

    data, out = Path(args.data), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    body = load_body_model(None)
    metas = _originals(data)[: args.limit]
    poses, roots, contacts, betas, lengths, clips = [], [], [], [], [], []
    for m in metas:
        cid = m["id"]
        b = np.load(data / "betas" / f"{cid}.npy").astype(np.float32).reshape(10)
        p = np.load(data / "poses" / f"{cid}.npy")[:, :22]
        rest0 = body.rest_joints(torch.as_tensor(b)[None])[0, 0].numpy()
        poses.append(p.astype(np.float32))
        roots.append((np.load(data / "transl" / f"{cid}.npy") + rest0).astype(np.float32))
        contacts.append(np.load(data / "contacts" / f"{cid}.npy").astype(np.uint8))
        betas.append(b)
        lengths.append(len(p))
        clips.append({"id": cid, "split": m["split"], "labels": m.get("labels") or {}, "dataset": m.get("dataset")})
    with atomic_path(out / PACK) as tmp:
        with open(tmp, "wb") as fh:
            n = np.asarray(lengths, np.int64)
            np.savez_compressed(fh, poses=squeeze(np.concatenate(poses), RAD, n),
                                root=squeeze(np.concatenate(roots), MM, n),
                                contacts=np.concatenate(contacts), betas=np.stack(betas), lengths=n)
    atomic_write_json(out / CLIPS, clips)
    mib = sum(f.stat().st_size for f in out.iterdir()) / 2 ** 20
    print(f"packed {len(clips)} takes, {sum(lengths)} frames: {mib:.1f} MiB in {out}")


# -- on the GPU machine ------------------------------------------------------------------------------

_PROC = None


def _worker_init():
    global _PROC
    import torch

    from shapemove.core.data.build import ClipProcessor

    torch.set_num_threads(1)
    _PROC = ClipProcessor()


def _variants(job):
    """Every dataset clip made from one take: [(id, betas, norm features, shape-aware features, contacts)]."""
    from shapemove.core.data.build import _augment_body
    from shapemove.core.data.mirror import mirror_contacts, mirror_rotations
    from shapemove.core.geometry.rotations import axis_angle_to_matrix

    cid, pose, root, contact, fitted, split, bodies = job
    proc = _PROC
    import torch

    rot22 = axis_angle_to_matrix(pose.astype(np.float32))
    rot = np.concatenate([rot22, np.broadcast_to(np.eye(3, dtype=np.float32), (len(rot22), 2, 3, 3))], axis=1)
    rest = proc.body.rest_joints(torch.as_tensor(fitted)[None])[0].numpy()
    sides = [("", rot, root, contact)]
    if split == "train":
        mroot = root * np.array([-1.0, 1.0, 1.0], np.float32)
        sides.append(("_mirror", mirror_rotations(rot), mroot, mirror_contacts(contact)))
    pmap = getattr(proc.body, "phenotype_map", None)
    out = []
    for tag, r, rt, c in sides:
        canon = proc.pose_on(r, rt, np.zeros(10, np.float32), proc.stride_scale(rest, None), c)
        norm = proc.features(canon, r, c)
        targets = [(f"{cid}{tag}", fitted, 1.0)]
        if split == "train":
            for k in range(bodies):
                b, _ = _augment_body(f"{cid}{tag}_b{k}", pmap, pmap.r2 if pmap is not None else None)
                targets.append((f"{cid}{tag}_b{k}", b.astype(np.float32), proc.stride_scale(rest, b)))
        for vid, b, scale in targets:
            shaped = proc.pose_on(r, rt, b, scale, c)
            out.append((vid, b, norm, proc.features(shaped, r, c), c))
    return out


def rebuild(pack_dir: Path, folder: Path, bodies: int, workers: int, minutes: float = 1e9) -> dict:
    """A dataset folder (``MotionClips`` reads it) rebuilt from a pack, the takes in a seeded random
    order, stopped after ``minutes`` (the takes not reached are left out); returns counts and seconds."""
    from multiprocessing import Pool

    from tqdm import tqdm

    from shapemove.core.motion.features import mean_std

    t0 = time.time()
    z = np.load(pack_dir / PACK, allow_pickle=False)
    clips = json.loads((pack_dir / CLIPS).read_text())
    ends = np.cumsum(z["lengths"])
    starts = ends - z["lengths"]
    n = z["lengths"]
    poses, root = unsqueeze(z["poses"], RAD, n, (22, 3)), unsqueeze(z["root"], MM, n, (3,))
    contacts, betas = z["contacts"], z["betas"]
    for sub in ("norm_joint_vecs", "new_joint_vecs", "betas", "contacts", "meta"):
        (folder / sub).mkdir(parents=True, exist_ok=True)
    order = np.random.default_rng(0).permutation(len(clips))   # a cut-short rebuild keeps a fair sample
    clips = [clips[i] for i in order]
    jobs = [(c["id"], poses[starts[i]:ends[i]], root[starts[i]:ends[i]], contacts[starts[i]:ends[i]], betas[i],
             c["split"], bodies) for c, i in zip(clips, order)]
    split_ids = {"train": [], "val": []}
    train_feats = []
    frames, done = 0, 0
    with Pool(workers, initializer=_worker_init) as pool:
        for c, made in tqdm(zip(clips, pool.imap(_variants, jobs, chunksize=4)), total=len(jobs), desc="features",
                            mininterval=10):
            if time.time() - t0 > minutes * 60:
                pool.terminate()
                break
            done += 1
            for vid, b, norm, shaped, con in made:
                np.save(folder / "norm_joint_vecs" / f"{vid}.npy", norm)
                np.save(folder / "new_joint_vecs" / f"{vid}.npy", shaped)
                np.save(folder / "betas" / f"{vid}.npy", b)
                np.save(folder / "contacts" / f"{vid}.npy", con)
                (folder / "meta" / f"{vid}.json").write_text(json.dumps({"id": vid, "split": c["split"], "labels": c["labels"]}))
                split_ids[c["split"]].append(vid)
                frames += len(shaped)
                if c["split"] == "train" and not vid.endswith(tuple(f"_b{k}" for k in range(bodies))):
                    train_feats += [norm, shaped]
    for s, ids in split_ids.items():
        (folder / f"{s}.txt").write_text("".join(i + "\n" for i in ids))
    (folder / "test.txt").write_text("")
    mean, std = mean_std(train_feats)
    np.save(folder / "Mean.npy", np.asarray(mean, np.float32))
    np.save(folder / "Std.npy", np.asarray(std, np.float32))
    return {"takes": len(clips), "takes_used": done, "train_clips": len(split_ids["train"]), "val_clips": len(split_ids["val"]),
            "frames": int(frames), "seconds": round(time.time() - t0, 1)}


def train(args) -> None:
    import torch

    from shapemove.core.models.savae import SAVAEConfig
    from shapemove.core.train.train_vae import train_vae

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    folder = Path(args.work)
    built = rebuild(Path(args.pack), folder, args.bodies, args.workers, args.rebuild_minutes)
    print("rebuilt:", json.dumps(built), flush=True)
    cfg = SAVAEConfig.load(str(args.config))
    cfg.train.resident = True
    minutes = args.minutes - (time.time() - t0) / 60
    run = folder.parent / "run"
    device = "cuda" if torch.cuda.is_available() else "cpu"
    metrics = train_vae(folder, run, cfg, steps=args.steps, device=device, minutes=minutes, verbose=False,
                        progress=lambda f, m: print(f"{time.time() - t0:6.0f} s  {m}", flush=True))
    from safetensors.torch import save_file

    from shapemove.core.train.checkpoint import load_checkpoint

    ck = load_checkpoint(run / "savae.pt", map_location="cpu", kind="savae")
    save_file({k: v.half().contiguous() if v.is_floating_point() else v.contiguous()
               for k, v in ck["model"].items()}, str(out / "savae16.safetensors"))
    meta = dict(ck["metadata"])
    (out / "meta.json").write_text(json.dumps(meta))
    (out / "log.jsonl").write_bytes((run / "log.jsonl").read_bytes())
    (out / "summary.json").write_text(json.dumps({"rebuilt": built, "metrics": metrics, "device": device,
                                                  "gpu": torch.cuda.get_device_name(0) if device == "cuda" else None,
                                                  "seconds": round(time.time() - t0, 1)}, indent=1))
    print("done in", round(time.time() - t0), "s", flush=True)


def unpack(args) -> None:
    import torch
    from safetensors.torch import load_file

    from shapemove.core.train.checkpoint import save_checkpoint

    state = Path(args.state)
    meta = json.loads((state / "meta.json").read_text())
    weights = {k: v.float() if v.is_floating_point() else v for k, v in load_file(str(state / "savae16.safetensors")).items()}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    save_checkpoint(out / "savae.pt", {"model": weights}, meta)
    for name in ("log.jsonl", "summary.json"):
        if (state / name).is_file():
            (out / name).write_bytes((state / name).read_bytes())
    from shapemove.core.models.savae import load_savae

    model = load_savae(out / "savae.pt")
    print(f"unpacked {out / 'savae.pt'}: {sum(p.numel() for p in model.parameters()):,} parameters, step {meta.get('step')}")
    del torch


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="verb", required=True)
    p = sub.add_parser("pack")
    p.add_argument("--data", type=Path, required=True)
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--limit", type=int, default=None, help="the first N takes only (a smoke test)")
    t = sub.add_parser("train")
    t.add_argument("--pack", type=Path, required=True)
    t.add_argument("--config", type=Path, required=True)
    t.add_argument("--minutes", type=float, default=7.0, help="wall-clock budget, rebuilding the features included")
    t.add_argument("--steps", type=int, default=None, help="a ceiling on the step count (default: the config's)")
    t.add_argument("--bodies", type=int, default=1, help="sampled bodies per training take (each also mirrored)")
    t.add_argument("--workers", type=int, default=os.cpu_count())
    t.add_argument("--rebuild-minutes", type=float, default=3.0, help="the features' share of the budget at most")
    t.add_argument("--work", type=Path, default=Path("/tmp/codec_data/built"))
    t.add_argument("--out", type=Path, required=True)
    u = sub.add_parser("unpack")
    u.add_argument("--state", type=Path, required=True)
    u.add_argument("--out", type=Path, required=True)
    args = ap.parse_args(argv)
    {"pack": pack, "train": train, "unpack": unpack}[args.verb](args)


if __name__ == "__main__":
    main()
