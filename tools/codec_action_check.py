"""Does the codec keep the action? Real clips of each action are encoded and decoded by an SA-VAE,
and the decoded motion is judged as ``eval paraphrase`` judges a generated one: the action of its 5
nearest training clips, by TMA embedding and by raw features, the clip's own take left out
(``eval/action_classifier.py``). A clip whose capture the judge itself misreads is not counted.

    python tools/codec_action_check.py --checkpoint weights/default/savae.pt --data data/built \
        [--split train] [--per-action 6] [--search] [--json out/codec_actions.json]

For each action (up to ``--per-action`` captured clips, not mirrors, shape-augmented copies or
compositions; drawn with seed 0) it prints how many the judge reads right from the capture, and of
those how many it still reads right decoded from the base codes (what the T5 writes and the
generator plays) and from both codes (a residual codec: retargeting, a user's library). A motion
the base codes cannot carry, no prompt can ask for: this is the ceiling the codec puts on each
action. The model folder's TMA (``--model``, default weights/default) is the TMA judge.

``--search``: the codes retargeting uses (searched for on the clip's own body, ``code_search``)
instead of the encoders'. Each clip also gets the error of its full codes decoded on its own body
(``generation/take_fidelity.py``: mean and worst second, mm), and the table ends with how well that
error tells the clips whose decoded action is lost (the TMA judge) from those it keeps: what
retargeting's fallback threshold ``LOST_TAKE_MM`` is chosen by.
"""
from __future__ import annotations

import argparse
import json
import random
from pathlib import Path

import numpy as np


def captured_clips(data: Path, split: str, actions: list[str], per_action: int, seed: int = 0) -> list[tuple[str, str]]:
    """(action, clip id): up to ``per_action`` captured clips of each action (their main label),
    drawn with ``seed``; mirror images, shape-augmented copies and compositions left out."""
    from shapemove.core.data.built_meta import read_meta
    from shapemove.core.eval.action_classifier import clip_actions

    ids = [i for i in (Path(data) / f"{split}.txt").read_text(encoding="utf-8").split() if i]
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


def separation(rows: list[dict], way: str) -> str:
    """How well the worst second's error (full codes on the clip's own body) tells the clips whose
    decoded action the TMA judge loses from those it keeps (clips whose capture it reads right):
    for each threshold, kept clips above it (a fallback that was not needed) and lost clips under
    it (a lost take still retargeted through the codes)."""
    judged = [r for r in rows if r["tma"]["capture"] == r["action"]]
    lost = sorted(r["worst_second_mm"] for r in judged if r["tma"][way] != r["action"])
    kept = sorted(r["worst_second_mm"] for r in judged if r["tma"][way] == r["action"])
    if not lost or not kept:
        return f"worst second: {len(lost)} lost, {len(kept)} kept clips (nothing to separate)"
    lines = [f"worst second (mm), {way} codes on the clip's own body: lost {len(lost)} clips, median "
             f"{np.median(lost):.0f}; kept {len(kept)}, median {np.median(kept):.0f}",
             "threshold  kept above (needless fallback)  lost under (missed)"]
    for t in (40, 50, 60, 70, 80, 90, 100, 120, 150):
        lines.append(f"{t:9d}  {sum(v > t for v in kept):30d}  {sum(v <= t for v in lost):19d}")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--checkpoint", type=Path, required=True, help="the SA-VAE (savae.pt) to check")
    p.add_argument("--data", type=Path, required=True, help="the built dataset (clips and the judges' references)")
    p.add_argument("--model", type=Path, default=None, help="model folder whose TMA judges (default weights/default)")
    p.add_argument("--split", default="train", help="clips to encode (default train: rare actions have few test clips)")
    p.add_argument("--per-action", type=int, default=6)
    p.add_argument("--search", action="store_true", help="the codes retargeting uses: searched on the clip's body")
    p.add_argument("--json", type=Path, default=None)
    a = p.parse_args(argv)

    import torch
    from tqdm import tqdm

    from shapemove.core.eval.action_classifier import ActionClassifier
    from shapemove.core.eval.tma_embed import load_tma
    from shapemove.core.generation.decode import decode_features
    from shapemove.core.generation.model_bundle import model_files, resolve_model_dir
    from shapemove.core.generation.retarget import encode_take
    from shapemove.core.generation.take_fidelity import take_error_mm, worst_second_mm
    from shapemove.core.models.known_texts import read_known
    from shapemove.core.models.motion_codes import base_of
    from shapemove.core.models.savae import load_savae
    from shapemove.core.torch_threads import one_torch_thread

    model_dir = resolve_model_dir(a.model)
    tma = load_tma(model_files(model_dir)["tma"])
    actions = read_known(model_dir / "t5").action_names
    vae = load_savae(a.checkpoint)
    judges = {"tma": ActionClassifier.from_data(tma, a.data, actions, progress=False),
              "raw": ActionClassifier.from_features(a.data, actions, progress=False)}
    ways = ["base"] + (["both"] if vae.has_residual else [])
    rows = []
    with one_torch_thread():
        for action, cid in tqdm(captured_clips(a.data, a.split, actions, a.per_action), desc="clips", unit="clip"):
            canon = np.load(a.data / "norm_joint_vecs" / f"{cid}.npy")
            n = len(canon) // vae.cfg.downsample * vae.cfg.downsample
            if n < 4 * vae.cfg.downsample:
                continue
            shaped = np.load(a.data / "new_joint_vecs" / f"{cid}.npy")[:n]
            betas = np.load(a.data / "betas" / f"{cid}.npy").astype(np.float32)
            if a.search:   # retargeting's codes
                tokens = encode_take(vae, canon, betas, shaped, search=True)
            else:
                with torch.no_grad():
                    tokens = encode_take(vae, canon, search=False)   # the encoders' codes
            with torch.no_grad():
                feats = [shaped] + [decode_features(base_of(tokens, vae.quantizer.codebook_size) if w == "base"
                                                    else tokens, vae, betas).numpy() for w in ways]
                err = take_error_mm(tokens, vae, betas, shaped)
            row = {"clip": cid, "action": action, "error_mm": float(err.mean()), "worst_second_mm": worst_second_mm(err)}
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
    head = "action".ljust(24) + "clips" + "".join(f"  {j}: capture " + " ".join(ways) for j in judges)
    print(head)
    for act, d in list(per.items()) + [("all", total)]:
        print(act.ljust(24) + f"{d['clips']:5d}" + "".join(
            f"  {j}: {d[f'{j}_capture']:7d} " + " ".join(f"{d[f'{j}_{w}']:{len(w)}d}" for w in ways) for j in judges))
    print(separation(rows, ways[-1]))
    if a.json:
        from shapemove.core.atomic import atomic_write_json

        atomic_write_json(a.json, {"checkpoint": str(a.checkpoint), "split": a.split, "per_action": per,
                                   "all": total, "rows": rows})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
