"""Body shape from text: how close the T5's `[BETA]` head gets to the body a shape text describes.

    res = eval_shape("weights/default", bodies=200)
    res["numeric"]["height_err_cm"], res["numeric"]["waist_err_cm"], res["adjectives"]["in_range"]

Bodies are NEW: betas drawn from N(0,1) (clipped to +-2.5, the builder's augmentation law) with a
seed, so none is a training body. Each body is measured on its mesh (``body.measure``: height,
chest/waist/hip girths as cross-section perimeters) and described in the dataset's numeric forms
(``data.shape_text``: the paper's long sentence, short centimetre/metre texts, feet and inches);
the head reads each text beside a motion caption, and its betas are measured on the mesh the same
way. The mesh measurement is independent of the betas -> girth regression the head was trained
against (``train/beta_head_refit.py``).

Size words: every word of ``shape_text.ADJECTIVES`` in "a WORD person" (or "a person WORD" for
"of average height/build") beside each caption; the share of predicted bodies inside the word's
written ranges (``shape_text.in_range``: "tall" 180-190 cm, "slim" waist < 0.43 x height, ...).

Errors are rounded-number limited: the texts state whole centimetres (feet/inches: whole inches,
up to 1.27 cm of height rounding).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from ..data.shape_text import ADJECTIVES, in_range, numeric_shape_text, shape_sentence
from ..errors import ShapeMoveError
from .report import show_result

CAPTIONS = ("a person walks forward.", "someone waves with the right hand.", "a person jumps in place.")
FORMS = ("sentence", "centimetres", "metres", "feet and inches")


def text_form(text: str) -> str:
    """Which numeric form a shape text is: the long sentence, cm, m or feet/inches."""
    if "circumference of" in text and "arm length" in text:
        return "sentence"
    if " ft " in text or "'" in text:
        return "feet and inches"
    return "metres" if " m tall" in text else "centimetres"


def _word_text(word: str) -> str:
    return f"a person {word}" if word.startswith("of ") else f"{'an' if word[0] in 'aeiou' else 'a'} {word} person"


@torch.no_grad()
def head_betas(t5, reader, motion_texts: list[str], shape_texts: list[str], batch: int = 64) -> np.ndarray:
    """(N, 10) betas the `[BETA]` head predicts for (motion text, shape text) pairs."""
    out = []
    for s in range(0, len(motion_texts), batch):
        inputs = t5.inputs_for(reader, motion_texts[s:s + batch], shape_texts[s:s + batch])
        out.append(t5.predict_betas(inputs).numpy())
    return np.concatenate(out) if out else np.zeros((0, 10), np.float32)


def head_readings(t5, reader, motion_texts: list[str], shape_texts: list[str]) -> tuple:
    """``head_betas``, with the texts the head refuses (a size it reads that no body has:
    ``beta_head.refuse_impossible``) as NaN rows: ((N, 10) betas, [(text, message)] refused)."""
    try:
        return head_betas(t5, reader, motion_texts, shape_texts), []
    except ShapeMoveError:   # some text of a batch refused: read them one by one
        out, refused = np.full((len(shape_texts), 10), np.nan, np.float32), []
        for i, (m, s) in enumerate(zip(motion_texts, shape_texts)):
            try:
                out[i] = head_betas(t5, reader, [m], [s])[0]
            except ShapeMoveError as exc:
                refused.append((s, str(exc)))
        return out, refused


def eval_shape(model_dir=None, bodies: int = 200, seed: int = 0, progress: bool = True) -> dict:
    from tqdm import tqdm

    from ..body.load import load_body_model
    from ..body.measure import measure
    from ..generation.model_bundle import model_files, resolve_model_dir
    from ..models.shapemove_t5 import ShapeMoveT5

    if not 1 <= int(bodies) <= 10_000:
        raise ShapeMoveError(f"--bodies must be between 1 and 10000, got {bodies}")
    t5_dir = model_files(resolve_model_dir(model_dir))["t5"]
    if not t5_dir.is_dir():
        raise ShapeMoveError(f"{t5_dir.parent} has no t5/ model: the [BETA] head lives there")
    t5, reader = ShapeMoveT5.load(t5_dir)
    body = load_body_model(None)
    rng = np.random.default_rng(seed)
    betas = np.clip(rng.standard_normal((int(bodies), body.num_betas)), -2.5, 2.5).astype(np.float32)
    truth = measure(body, betas)
    rows = []
    for i in range(len(betas)):
        m = {k: float(v[i]) for k, v in truth.items()}
        texts = {shape_sentence(m)} | {numeric_shape_text(m, f"eval/{seed}/{i}/{k}") for k in range(4)}
        for t in sorted(texts):
            rows.append({"body": i, "text": t, "form": text_form(t), "caption": CAPTIONS[len(rows) % len(CAPTIONS)]})
    pred = head_betas(t5, reader, [r["caption"] for r in rows], [r["text"] for r in rows])
    got = {k: [] for k in ("height_cm", "waist_cm")}
    for s in tqdm(range(0, len(pred), 64), desc="measure predicted bodies", unit="batch", disable=not progress):
        mm = measure(body, pred[s:s + 64])
        for k in got:
            got[k].append(np.atleast_1d(mm[k]))
    got = {k: np.concatenate(v) for k, v in got.items()}
    for j, r in enumerate(rows):
        r["height_err_cm"] = abs(float(got["height_cm"][j]) - float(truth["height_cm"][r["body"]]))
        r["waist_err_cm"] = abs(float(got["waist_cm"][j]) - float(truth["waist_cm"][r["body"]]))

    def summary(sel):
        return {"texts": len(sel), "height_err_cm": float(np.mean([r["height_err_cm"] for r in sel])) if sel else None,
                "waist_err_cm": float(np.mean([r["waist_err_cm"] for r in sel])) if sel else None}

    numeric = {**summary(rows), "per_form": {f: summary([r for r in rows if r["form"] == f]) for f in FORMS}}
    # size words
    words = sorted(ADJECTIVES)
    wt = [(w, c) for w in words for c in CAPTIONS]
    wp = head_betas(t5, reader, [c for _, c in wt], [_word_text(w) for w, _ in wt])
    wm = measure(body, wp)
    per_word: dict = {}
    for j, (w, _) in enumerate(wt):
        ok = in_range(w, float(wm["height_cm"][j]), float(wm["waist_cm"][j]))
        d = per_word.setdefault(w, {"n": 0, "in_range": 0, "height_cm": [], "waist_to_height": []})
        d["n"] += 1
        d["in_range"] += ok
        d["height_cm"].append(float(wm["height_cm"][j]))
        d["waist_to_height"].append(float(wm["waist_cm"][j] / wm["height_cm"][j]))
    per_word = {w: {"n": d["n"], "in_range": d["in_range"] / d["n"], "height_cm": float(np.mean(d["height_cm"])),
                    "waist_to_height": float(np.mean(d["waist_to_height"])),
                    "ranges": {"height_cm": ADJECTIVES[w][0], "waist_to_height": ADJECTIVES[w][1]}}
                for w, d in per_word.items()}
    adjectives = {"in_range": float(np.mean([d["in_range"] for d in per_word.values()])), "per_word": per_word}
    return {"bodies": int(bodies), "seed": int(seed), "model": str(t5_dir), "numeric": numeric, "adjectives": adjectives}


def format_results(res: dict) -> str:
    n = res["numeric"]
    lines = [f"[BETA] head on {res['bodies']} new bodies (N(0,1) betas, seed {res['seed']}), measured on the mesh",
             f"{'numeric form':18s} {'texts':>5s} {'height err':>10s} {'waist err':>9s}"]
    for f, d in n["per_form"].items():
        if d["texts"]:
            lines.append(f"{f:18s} {d['texts']:5d} {d['height_err_cm']:8.2f} cm {d['waist_err_cm']:7.2f} cm")
    lines.append(f"{'all numeric':18s} {n['texts']:5d} {n['height_err_cm']:8.2f} cm {n['waist_err_cm']:7.2f} cm")
    lines.append("size words: share of predicted bodies inside the word's ranges (mean height, waist/height)")
    for w, d in res["adjectives"]["per_word"].items():
        lines.append(f"  {w:20s} {100 * d['in_range']:5.0f} %   {d['height_cm']:6.1f} cm  {d['waist_to_height']:.3f}")
    lines.append(f"all words: {100 * res['adjectives']['in_range']:.1f} % in range")
    return "\n".join(lines)


def add_arguments(p) -> None:
    from .report import add_output_arguments

    p.add_argument("--model", type=Path, default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--bodies", type=int, default=200, help="number of new random bodies (default 200)")
    p.add_argument("--seed", type=int, default=0)
    add_output_arguments(p)


def from_cli(args) -> int:
    res = eval_shape(args.model, args.bodies, args.seed, progress=not args.quiet)
    return show_result(format_results(res), res, args.json)
