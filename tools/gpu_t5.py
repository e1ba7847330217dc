"""Train ShapeMove's T5 on a lent GPU machine that holds no ShapeMove data, in three steps.

    python tools/gpu_t5.py pack --data data/built --vae weights/default/savae.pt --tokens runs/t5/tokens.npz --out .gpu
    python tools/gpu_t5.py train --pack .gpu --configs A.json B.json --minutes 7 --out $OUT   # there
    python tools/gpu_t5.py unpack --state $OUT/A --tokens runs/t5/tokens.npz --out runs/gpu_a   # here

Only 64 MiB travel to the GPU machine, the repository included, so ``pack`` writes what
``train_t5`` reads and nothing else: the training split's captions, shape texts, betas and clip meta
(a tar), the SA-VAE (named, not copied, when it is the repository's own file) and the FSQ tokens it
gave every clip (``tokens.npz`` of a ``train t5`` run, refused unless it was made by that very VAE
file: a T5 trained on another codec's tokens writes motions the shipped decoder reads as noise),
and the frozen MiniLM in float16 with only the rows of its word-piece
table that the training texts use (the bank's sentences sampled exhaustively): about 24 MB instead of
the 83 MB package. Its token states differ from the float32 encoder's by float16 rounding, the same
rounding ``StateCache`` applies to every state it keeps.

``train`` runs one ``train_t5`` per config at once on the one GPU, each stopped cleanly at its
step count (set from a timed probe so all finish inside ``--minutes``), and writes each run's
weights (float16 safetensors, under the 16 MiB a file that come back) and its log.

``unpack`` loads those weights into the model the config describes and saves a model folder here,
with the known captions' vectors from the exact float32 encoder (``known_texts.py``) and, for a
model that reads retrieved clips, the memory built from the training set. Train the [BETA] head on
it with ``train head`` as ``make train-default`` does.
"""
from __future__ import annotations

import argparse
import json
import random
import sys
import tarfile
import time
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT.parent))

DATA_FILES = ("texts", "shape_texts", "betas", "meta")
WEIGHTS = "model.safetensors"  # of the encoder's files (``text_encoder.FILES``), the one packed in float16
PROBE = 300  # steps timed before the step count is set
BANK_SAMPLES = 400  # bank sentences drawn per action (and per action pair) to collect word pieces


def _training_texts(data: Path, ids: list[str]) -> list[str]:
    from shapemove.core.data.actions import ACTIONS
    from shapemove.core.data.paraphrase_bank import sentence, sequence_sentence
    from shapemove.core.train.t5_dataset import all_texts, body_words
    from shapemove.core.data.built_meta import clip_meta

    texts = set(all_texts(data, ids))
    rng = random.Random(0)
    names = sorted(ACTIONS)
    for a in names:
        texts.update(sentence(a, rng) for _ in range(BANK_SAMPLES))
    for _ in range(BANK_SAMPLES * 20):
        texts.add(sequence_sentence(rng.sample(names, rng.choice((2, 3))), rng))
    for c in ids:
        texts.update(body_words(clip_meta(data, c), np.load(data / "betas" / f"{c}.npy"), c))
    return sorted(texts)


def _pack_vae(vae: Path, out: Path) -> None:
    """The VAE into the pack: a file of the repository (which travels anyway) is named in
    ``vae.txt``, any other is copied as ``savae.pt``."""
    vae = Path(vae).resolve()
    if vae.is_relative_to(ROOT):
        (out / "savae.pt").unlink(missing_ok=True)
        (out / "vae.txt").write_text(vae.relative_to(ROOT).as_posix())
    else:
        (out / "vae.txt").unlink(missing_ok=True)
        (out / "savae.pt").write_bytes(vae.read_bytes())


def _vae_of(pack: Path) -> Path:
    """The packed VAE's path on this machine (``_pack_vae``)."""
    named = pack / "vae.txt"
    return ROOT / named.read_text().strip() if named.is_file() else pack / "savae.pt"


def pack(args) -> None:
    from safetensors.torch import load_file, save_file

    from shapemove.core.models.text_encoder import FILES, extract, load_text_encoder
    from shapemove.core.train.motion_dataset import read_split
    from shapemove.core.train.train_t5 import vae_stamp

    data, out = args.data, args.out
    out.mkdir(parents=True, exist_ok=True)
    ids = sorted(set(read_split(data, "train")) | set(read_split(data, "val")))
    with tarfile.open(out / "data.tar.gz", "w:gz") as tar:
        for split in ("train", "val"):
            tar.add(data / f"{split}.txt", f"{split}.txt")
        for c in ids:
            for d in DATA_FILES:
                f = data / d / f"{c}.{'npy' if d == 'betas' else 'json' if d == 'meta' else 'txt'}"
                if f.is_file():
                    tar.add(f, f"{d}/{f.name}")
    z = np.load(args.tokens, allow_pickle=False)
    if str(z["__vae__"]) != vae_stamp(args.vae):
        raise SystemExit(f"{args.tokens} holds the tokens of {str(z['__vae__']).rsplit(':', 1)[0]}, not of {args.vae}")
    np.savez_compressed(out / "tokens.npz", **{k: z[k] for k in z.files if k != "__vae__"})
    _pack_vae(args.vae, out)
    enc = load_text_encoder()
    used = set(enc.special_ids) | {enc.unk_id}   # [PAD] [UNK] [CLS] [SEP] [MASK]
    texts = _training_texts(data, ids)
    for s in range(0, len(texts), 4096):
        for e in enc.tokenizer.encode_batch(texts[s:s + 4096]):
            used.update(e.ids)
    folder = extract()
    w = load_file(str(folder / WEIGHTS))
    rows = torch.tensor(sorted(used))
    w16 = {k: v.half().contiguous() for k, v in w.items() if k != "embeddings.word_embeddings.weight"}
    w16["kept_rows"] = rows
    w16["kept_embeddings"] = w["embeddings.word_embeddings.weight"][rows].half().contiguous()
    save_file(w16, str(out / "minilm16.safetensors"), metadata={"vocab": str(w["embeddings.word_embeddings.weight"].shape[0])})
    for name in FILES:
        if name != WEIGHTS:
            (out / name).write_bytes((folder / name).read_bytes())
    print(f"{len(texts)} texts, {len(used)} word pieces kept; "
          f"{sum(f.stat().st_size for f in out.iterdir()) / 2**20:.1f} MiB in {out}")


def _encoder_from_pack(p: Path, cache: Path) -> None:
    """Rebuild the MiniLM folder (float32, unused word pieces zero) where ``load_text_encoder``
    looks, and let it load without the float32 file's checksum (it cannot match)."""
    from safetensors import safe_open
    from safetensors.torch import load_file, save_file

    from shapemove.core.models import text_encoder as te

    folder = cache / f"{te.NAME}-{te.MODEL_SHA256[:12]}"
    folder.mkdir(parents=True, exist_ok=True)
    w = load_file(str(p / "minilm16.safetensors"))
    with safe_open(str(p / "minilm16.safetensors"), "pt") as f:
        vocab = int(f.metadata()["vocab"])
    emb = torch.zeros(vocab, w["kept_embeddings"].shape[1])
    emb[w.pop("kept_rows")] = w.pop("kept_embeddings").float()
    full = {k: v.float() for k, v in w.items()} | {"embeddings.word_embeddings.weight": emb}
    save_file(full, str(folder / WEIGHTS))
    for name in te.FILES:
        if name != WEIGHTS:
            (folder / name).write_bytes((p / name).read_bytes())
    te.set_cache_dir(cache)
    te._verify = lambda folder: None  # the float16 copy: checked by the pack's own use, not the sha
    if torch.cuda.is_available():  # read the captions on the GPU too (57,000 texts: seconds, not minutes)
        m = te.load_text_encoder().model
        m.w = {k: v.cuda() for k, v in m.w.items()}
        forward = m.forward
        m.forward = lambda ids, mask, types: forward(ids.cuda(), mask.cuda(), types.cuda()).cpu()


def train_one(args) -> None:
    """One config on the GPU (a process of its own: ``train`` starts one per config)."""
    from safetensors.torch import save_file

    from shapemove.core.train.train_t5 import T5TrainConfig, train_t5, vae_stamp

    p = args.pack
    work = Path(args.work)
    name = args.config.stem
    _encoder_from_pack(p, work / f"encoder_{name}")
    data = work / "data"
    c = T5TrainConfig.load(str(args.config))
    run = work / name
    run.mkdir(parents=True, exist_ok=True)
    vae = _vae_of(p)
    z = np.load(p / "tokens.npz")   # the cache train_t5 reads, stamped for the VAE's copy here
    np.savez(run / "tokens.npz", __vae__=np.array(vae_stamp(vae)), **{k: z[k] for k in z.files})
    torch.set_num_threads(2)
    deadline = time.time() + args.seconds
    c.steps, c.head_steps = args.steps, 0
    t0, seen = time.time(), {"calls": 0, "first": 0.0}

    def cancel():  # called before every step: after PROBE steps, fit the step count to the time left
        seen["calls"] += 1
        if seen["calls"] == 1:
            seen["first"] = time.time()  # the captions are read by now
        elif seen["calls"] == args.probe:  # before the warm-up ends, so the schedule never jumps
            rate = (args.probe - 1) / (time.time() - seen["first"])
            c.steps = min(c.steps, int(args.probe + 0.9 * rate * (deadline - time.time())))
            print(name, f"{rate:.1f} steps/s: {c.steps} steps", flush=True)
        return time.time() > deadline

    metrics = train_t5(data, vae, run, c, device=args.device, cancel=cancel, verbose=False, resume=args.resume)
    ck = torch.load(run / "last.pt", map_location="cpu", weights_only=True)
    state = {k: (v.half() if v.is_floating_point() else v).contiguous() for k, v in ck["model"].items()}
    info = {"config": json.dumps(ck["config"]), "step": str(ck["step"]), "seconds": f"{time.time() - t0:.0f}",
            "metrics": json.dumps(metrics, default=str)}
    part, size, n = {}, 0, 0
    keys = sorted(state)
    for k in keys:  # files of at most ~14 MiB: what comes back from the machine is 16 MiB a file
        part[k] = state[k]
        size += state[k].numel() * state[k].element_size()
        if size > 14 << 20 or k == keys[-1]:
            save_file(part, str(args.out / f"{name}.{n}.safetensors"), metadata=info)
            part, size, n = {}, 0, n + 1
    print(name, "step", ck["step"], f"{time.time() - t0:.0f} s", flush=True)


def train(args) -> None:
    """Unpack the data once, then one ``train-one`` process per config, all at once within ``--minutes``."""
    import subprocess

    work = Path(args.work)
    (work / "data").mkdir(parents=True, exist_ok=True)
    with tarfile.open(args.pack / "data.tar.gz") as tar:
        tar.extractall(work / "data", filter="data")
    t_start = time.time()
    procs = []
    for cfg in args.configs:
        c = json.loads(cfg.read_text())
        steps = int(c["steps"])
        cmd = [sys.executable, __file__, "train-one", "--pack", str(args.pack), "--work", str(work),
               "--config", str(cfg), "--out", str(args.out), "--steps", str(steps),
               "--seconds", str(int(args.minutes * 60 - (time.time() - t_start))),
               "--device", args.device, "--probe", str(args.probe)] + (["--resume"] if args.resume else [])
        procs.append(subprocess.Popen(cmd))
    for pr in procs:
        pr.wait()


def unpack(args) -> None:
    from safetensors import safe_open
    from safetensors.torch import load_file

    from shapemove.core.models.known_texts import build_known
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5, size_from_dict
    from shapemove.core.models.text_encoder import StateCache, load_text_encoder
    from shapemove.core.train.motion_dataset import read_split
    from shapemove.core.train.t5_dataset import read_lines
    from shapemove.core.train.train_t5 import T5TrainConfig, load_vae

    parts = sorted(args.state.parent.glob(args.state.name + ".*.safetensors"))
    if not parts:
        raise SystemExit(f"no {args.state}.N.safetensors")
    with safe_open(str(parts[0]), "pt") as f:
        meta = f.metadata()
    c = T5TrainConfig(**json.loads(meta["config"]))
    vae = load_vae(args.vae)
    model = ShapeMoveT5.build_minilm(int(vae.quantizer.codebook_size), size_from_dict(c.size), beta_weight=c.beta_weight)
    state = {k: v.float() if v.is_floating_point() else v for p in parts for k, v in load_file(str(p)).items()}
    model.load_state_dict(state)
    model.eval()
    train_ids = read_split(args.data, "train")
    states = StateCache(load_text_encoder())
    memory = None
    if model.memory_k:
        from shapemove.core.models.motion_memory import MotionMemory

        z = np.load(args.tokens, allow_pickle=False)
        tokens = {k: z[k] for k in z.files if k != "__vae__"}
        states.add([t for cid in train_ids for t in read_lines(args.data / "texts" / f"{cid}.txt")])
        memory = MotionMemory.from_dataset(args.data, train_ids, tokens, states)
    info = {"vae": str(args.vae), "config": c.__dict__, "downsample": vae.cfg.downsample,
            "max_codes": c.max_codes, "data": str(args.data), "base_model": None, "step": int(meta["step"]),
            "trained_on": "GPU (tools/gpu_t5.py)"}
    model.save(args.out / "t5", None, info, known=build_known(args.data, train_ids, states), memory=memory)
    print(f"wrote {args.out / 't5'} (step {meta['step']})")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    run = argparse.ArgumentParser(add_help=False)   # what ``train`` passes on to each ``train-one``
    run.add_argument("--device", default="cuda")
    run.add_argument("--probe", type=int, default=PROBE)
    run.add_argument("--resume", action="store_true")
    a = sub.add_parser("pack")
    a.add_argument("--data", type=Path, default=Path("data/built"))
    a.add_argument("--vae", type=Path, default=Path("weights/default/savae.pt"))
    a.add_argument("--tokens", type=Path, required=True, help="tokens.npz of a train t5 run on that VAE")
    a.add_argument("--out", type=Path, default=Path(".gpu"))
    a = sub.add_parser("train", parents=[run])
    a.add_argument("--pack", type=Path, default=Path(".gpu"))
    a.add_argument("--configs", type=Path, nargs="+", required=True)
    a.add_argument("--minutes", type=float, default=7.0)
    a.add_argument("--work", default="/tmp/gpu_t5")
    a.add_argument("--out", type=Path, required=True)
    a = sub.add_parser("train-one", parents=[run])
    a.add_argument("--pack", type=Path, required=True)
    a.add_argument("--work", required=True)
    a.add_argument("--config", type=Path, required=True)
    a.add_argument("--out", type=Path, required=True)
    a.add_argument("--steps", type=int, required=True)
    a.add_argument("--seconds", type=int, required=True)
    a = sub.add_parser("unpack")
    a.add_argument("--state", type=Path, required=True)
    a.add_argument("--data", type=Path, default=Path("data/built"))
    a.add_argument("--vae", type=Path, default=Path("weights/default/savae.pt"))
    a.add_argument("--tokens", type=Path, required=True, help="the tokens.npz that was packed")
    a.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    {"pack": pack, "train": train, "train-one": train_one, "unpack": unpack}[args.cmd](args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
