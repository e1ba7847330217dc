"""Text-to-motion evaluation: generate one motion per clip of a split and score it beside the real clip.

    res = eval_generate("DATA", split="test", model_dir="weights/default")
    res["r_precision_top1"], res["ground_truth"]["r_precision_top1"]   # model vs the real-data ceiling

For every clip the prompt is one of its captions (chosen with ``seed``) and its numeric shape text
(line 1 of ``shape_texts/ID.txt``); the motion is as long as the real clip (capped at the T5's
``max_codes``). The result holds the ``KEYS`` of the generated motions and, under
"ground_truth", the same keys for the real clips (as ``eval recon`` does):

- r_precision_top1/top3, matching_score: TMA embeddings of the features of what the rig plays
  (``motion_features``; the real clips' own features) against
  the caption embeddings (groups of 32, ``retrieval.r_precision``);
- fid: Fréchet distance between the generated and the real motion embeddings (the real column
  is the real set against itself: 0 up to round-off, clipped at 0);
- penetrate_cm, float_cm, skate_pct, dyn_stable_pct: ``evaluate_motion`` on the body mesh posed
  with the motion's poses/transl and its betas (predicted for generated, fitted for real),
  pooled over all frames with ``aggregate``;
- height_err_cm, waist_err_cm: mean |measure(predicted betas) - measure(true betas)| (0 for real);
- clips: number of clips evaluated.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from ..generation.generate import Generator, Request
from ..generation.model_bundle import model_files
from ..geometry.rotations import axis_angle_to_matrix
from ..motion.features import motion_features
from ..train.motion_dataset import read_split
from ..train.t5_dataset import read_lines
from .evaluate import evaluate_motion
from .report import aggregate, show_result
from .tma_embed import embed_motions, embed_texts, load_tma

KEYS = ("r_precision_top1", "r_precision_top3", "matching_score", "fid", "penetrate_cm", "float_cm", "skate_pct",
        "dyn_stable_pct", "height_err_cm", "waist_err_cm", "clips", "penetrate_all_cm", "float_all_cm",
        "skate_joints_pct")
PHYSICS = ("penetrate_cm", "float_cm", "skate_pct", "dyn_stable_pct", "penetrate_all_cm", "float_all_cm", "skate_joints_pct")


def load_clips(data, split: str = "test", max_clips: int | None = None, seed: int = 0) -> list[dict]:
    """The clips of ``split`` that have captions, features, betas, poses and transl, as dicts:
    id, caption (one, chosen with ``seed``), shape_text (numeric sentence or None), features
    (T,263) shape-aware, betas (10,), poses (T,24,3) axis-angle, transl (T,3). ``max_clips``
    keeps a seeded random subset (in split order)."""
    root = Path(data)
    if not root.is_dir():
        raise ShapeMoveError(f"dataset folder not found: {root}")
    ids = read_split(root, split)
    if not ids:
        raise ShapeMoveError(f"{root}: split '{split}' is empty or missing ({split}.txt)")
    rng = np.random.default_rng(seed)
    clips = []
    for cid in ids:
        caps = read_lines(root / "texts" / f"{cid}.txt")
        files = {k: root / k / f"{cid}.npy" for k in ("new_joint_vecs", "betas", "poses", "transl")}
        if not caps or not all(f.is_file() for f in files.values()):
            continue
        shape = read_lines(root / "shape_texts" / f"{cid}.txt")
        clips.append({"id": cid, "caption": caps[int(rng.integers(len(caps)))], "shape_text": shape[0] if shape else None,
                      **{k: np.load(f).astype(np.float32) for k, f in files.items()}})
    if max_clips is not None:
        if max_clips < 2:
            raise ShapeMoveError(f"--max-clips must be at least 2 (R-precision ranks clips), got {max_clips}")
        if len(clips) > max_clips:
            keep = np.sort(rng.choice(len(clips), max_clips, replace=False))
            clips = [clips[i] for i in keep]
    if len(clips) < 2:
        raise ShapeMoveError(f"{root}: split '{split}' has {len(clips)} complete clip(s) (captions, features, betas, "
                             "poses, transl); need at least 2")
    for c in clips:
        c["features"] = c.pop("new_joint_vecs")
    return clips


def physics(body, betas, poses, transl) -> dict:
    """``evaluate_motion`` of one clip: betas (10,), poses (T,24,3) axis-angle, transl (T,3)."""
    rot = axis_angle_to_matrix(poses)
    return evaluate_motion(body, betas, rot, transl)


def shape_errors(body, predicted: np.ndarray, true: np.ndarray) -> tuple[float, float]:
    """Mean |height| and |waist| differences (cm) between bodies ``predicted`` and ``true`` (N,10)."""
    from ..body.measure import measure

    p, t = measure(body, np.asarray(predicted, np.float32)), measure(body, np.asarray(true, np.float32))
    return (float(np.abs(p["height_cm"] - t["height_cm"]).mean()),
            float(np.abs(p["waist_cm"] - t["waist_cm"]).mean()))


def score(tma, texts: list[str], feats: list, reference=None, clips_physics: list[dict] = (),
          height_err: float = 0.0, waist_err: float = 0.0) -> tuple[dict, np.ndarray]:
    """(the ``KEYS`` of one column, its motion embeddings). ``reference``: (N,E) real motion
    embeddings for FID (None: the column's own embeddings, i.e. the real-data ceiling)."""
    from .retrieval import fid, matching_score, r_precision

    model, tok, mean, std = tma
    t = embed_texts(model, tok, texts)
    m = embed_motions(model, feats, mean, std)
    r = r_precision(t, m, top_k=(1, 3))
    with warnings.catch_warnings():  # a few clips give singular covariances: sqrtm warns, the value is fine
        warnings.simplefilter("ignore")
        f = max(0.0, fid(m, m if reference is None else reference))
    phys = aggregate(list(clips_physics))
    out = {"r_precision_top1": r["top1"], "r_precision_top3": r["top3"], "matching_score": matching_score(t, m),
           "fid": f, **{k: float(phys[k]) for k in PHYSICS}, "height_err_cm": height_err, "waist_err_cm": waist_err,
           "clips": len(feats)}
    return out, m


def eval_generate(data, split: str = "test", model_dir=None, tma=None, max_clips: int | None = None, seed: int = 0,
                  progress=None, generator=None, candidates: int = 1) -> dict:
    """Generate one motion per clip of ``split`` and score it (``candidates``: best-of-N samples per
    prompt; 1 by default, because the product's choice among samples uses the same TMA that the
    R-precision, matching score and FID read and would flatter them); returns {KEYS..., "ground_truth":
    {KEYS}} (see the module docstring). ``tma``: a path (tma.pt or its folder), a
    ``load_tma`` tuple, or None for the model folder's ``tma/``. ``generator``: an already loaded
    ``Generator`` (then ``model_dir`` is ignored). progress(fraction, message) after each clip."""
    clips = load_clips(data, split, max_clips, seed)
    gen = generator if generator is not None else Generator(model_dir)
    if tma is None:
        tma = model_files(gen.model_dir)["tma"]
        if not tma.is_file():
            raise ShapeMoveError(f"{gen.model_dir} has no tma/tma.pt: pass --tma PATH (train one with `train tma`)")
    tma = load_tma(tma) if isinstance(tma, (str, Path)) else tma
    down = gen.vae.cfg.downsample
    max_s = gen.max_codes * down / FPS
    n = len(clips)
    step = lambda i, msg: progress((i + 1) / (2 * n), msg) if progress is not None else None  # noqa: E731

    motions = []
    for i, c in enumerate(clips):
        seconds = float(np.clip(len(c["features"]) / FPS, max(0.4, down / FPS), max_s))
        # the model's own reading of the shape text ([BETA] head), not the measurement fit
        req = Request(c["caption"], c["shape_text"], seconds=seconds, seed=seed + i, shape_from="head",
                      candidates=candidates)
        motions.append(gen.generate_batch([req])[0])
        step(i, f"generated {c['id']}")
    gen_phys, real_phys = [], []
    for i, (c, m) in enumerate(zip(clips, motions)):
        gen_phys.append(physics(gen.body, m.betas, m.poses, m.transl))
        real_phys.append(physics(gen.body, c["betas"], c["poses"], c["transl"]))
        step(n + i, f"scored {c['id']}")
    texts = [c["caption"] for c in clips]
    real, real_emb = score(tma, texts, [c["features"] for c in clips], None, real_phys)
    h, w = shape_errors(gen.body, np.stack([m.betas for m in motions]), np.stack([c["betas"] for c in clips]))
    generated, _ = score(tma, texts, [motion_features(m) for m in motions], real_emb, gen_phys, h, w)
    return {**generated, "ground_truth": real}


LABELS = {
    "r_precision_top1": ("R-precision top 1", "higher"), "r_precision_top3": ("R-precision top 3", "higher"),
    "matching_score": ("Matching score", "lower"), "fid": ("FID", "lower"), "penetrate_cm": ("Penetrate (cm)", "lower"),
    "float_cm": ("Float (cm)", "lower"), "skate_pct": ("Skate (%)", "lower"),
    "penetrate_all_cm": ("Penetrate, paper: all frames (cm)", "lower"),
    "float_all_cm": ("Float, paper: all frames (cm)", "lower"),
    "skate_joints_pct": ("Skate, GMD on the foot joints (%)", "lower"),
    "dyn_stable_pct": ("Dyn. stability (%)", "higher"), "height_err_cm": ("Height error (cm)", "lower"),
    "waist_err_cm": ("Waist error (cm)", "lower"),
}


def format_results(res: dict, title: str = "Text-to-motion evaluation") -> str:
    """The generated and real columns as a plain-text table."""
    g, r = res, res["ground_truth"]
    fmt = lambda v: "nan" if isinstance(v, float) and math.isnan(v) else f"{v:.3f}"  # noqa: E731
    rows = [(label, better, fmt(g[k]), fmt(r[k])) for k, (label, better) in LABELS.items()]
    head = ("metric", "better", "generated", "ground truth")
    w = [max(len(row[i]) for row in rows + [head]) for i in range(4)]
    line = lambda row: "  ".join(c.ljust(w[i]) if i < 2 else c.rjust(w[i]) for i, c in enumerate(row))  # noqa: E731
    sep = "-" * len(line(head))
    return "\n".join([f"{title} ({g['clips']} clips)", sep, line(head), sep] + [line(row) for row in rows] + [sep])


def add_arguments(p) -> None:
    """Options of `python -m shapemove eval generate`."""
    p.add_argument("--data", type=Path, required=True, help="dataset folder from `data build`")
    p.add_argument("--split", default="test", choices=["train", "val", "test"])
    p.add_argument("--json", type=Path, required=True, help="write the metrics here")
    p.add_argument("--model", type=Path, default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--tma", type=Path, default=None, help="TMA for the retrieval metrics (default: the model's tma/)")
    p.add_argument("--max-clips", type=int, default=None, help="evaluate a seeded random subset of N clips")
    p.add_argument("--seed", type=int, default=0, help="caption choice, clip subset and sampling seed")
    p.add_argument("--candidates", type=int, default=1,
                   help="token samples per prompt, the TMA keeping the closest (default 1: the TMA also scores)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def from_cli(args) -> int:
    """`python -m shapemove eval generate` (see ``add_arguments``): prints the table, writes the JSON."""
    from tqdm import tqdm

    split = getattr(args, "split", None) or "test"
    bar = tqdm(total=100, desc="eval generate", unit="%", disable=getattr(args, "quiet", False))

    def progress(frac, msg):
        bar.update(round(100 * frac) - bar.n)
        bar.set_postfix_str(msg)

    try:
        res = eval_generate(args.data, split, getattr(args, "model", None), getattr(args, "tma", None),
                            getattr(args, "max_clips", None), getattr(args, "seed", 0) or 0, progress=progress,
                            candidates=getattr(args, "candidates", 1))
    finally:
        bar.close()
    return show_result(format_results(res, f"Text-to-motion evaluation, {split} split"), res,
                       getattr(args, "json", None))
