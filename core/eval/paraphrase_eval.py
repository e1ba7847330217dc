"""Held-out paraphrase evaluation: does a prompt in words the captions never used give the right action?

    res = eval_paraphrase("weights/default")        # configs/heldout_paraphrases.json
    res["motion"]["accuracy"], res["motion"]["per_action"]["walk"]

For each held-out prompt ({"text", "action", "also"?}, written by hand, never trained or tuned on)
the model generates a motion; the TMA classifies it: its motion embedding against one text
embedding per action the model knows (the mean of the TMA's unit embeddings of "A person
{phrase}." over the action's caption phrases, ``core/data/actions.py``), nearest wins. Reported:

- ``motion``: the generated motion's action (the target: >= 80 % right);
- ``text``: the same classification of the prompt's own TMA text embedding (how well the text
  side reads the paraphrase, independent of the generator);
each strict (the expected action) and lenient (also one of "also"), per action and overall, over
the prompts whose action the model was trained on; prompts of actions it does not know are
counted apart (``unknown_action``). The TMA was trained on the training captions only, so it
was not tuned on these prompts either.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..atomic import atomic_write_json
from ..errors import ShapeMoveError

DEFAULT_PROMPTS = Path(__file__).resolve().parents[2] / "configs" / "heldout_paraphrases.json"
MAX_PROMPTS_BYTES = 4 << 20


def load_prompts(path=None) -> list[dict]:
    """The held-out prompts [{text, action, also: [..]}] of a JSON file ({"prompts": [...]} or a list)."""
    path = Path(path) if path else DEFAULT_PROMPTS
    if not path.is_file():
        raise ShapeMoveError(f"paraphrase file not found: {path}")
    if path.stat().st_size > MAX_PROMPTS_BYTES:
        raise ShapeMoveError(f"{path}: larger than {MAX_PROMPTS_BYTES >> 20} MB; not a prompt list")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ShapeMoveError(f"{path}: not valid JSON ({exc})") from None
    items = doc.get("prompts") if isinstance(doc, dict) else doc
    out = []
    for i, it in enumerate(items if isinstance(items, list) else []):
        if not (isinstance(it, dict) and isinstance(it.get("text"), str) and isinstance(it.get("action"), str)):
            raise ShapeMoveError(f"{path}: prompt {i} must be {{\"text\": ..., \"action\": ...}}")
        also = it.get("also") or []
        out.append({"text": it["text"], "action": it["action"], "also": [str(a) for a in also if isinstance(a, str)]})
    if not out:
        raise ShapeMoveError(f"{path}: no prompts (expected {{\"prompts\": [{{\"text\", \"action\"}}, ...]}})")
    return out


def action_texts(name: str) -> list[str]:
    """The caption-like sentences of an action: "A person {phrase}." for each of its phrases."""
    from ..data.actions import ACTIONS

    a = ACTIONS.get(name)
    phrases = list(a.phrases) if a is not None else [name]
    return [f"A person {p}." for p in phrases]


def action_embeddings(tma, actions: list[str]) -> np.ndarray:
    """(A, E) unit TMA text embedding per action (mean over its sentences)."""
    from .tma_embed import embed_texts

    model, tok, _, _ = tma
    out = []
    for a in actions:
        e = embed_texts(model, tok, action_texts(a)).mean(0)
        out.append(e / max(np.linalg.norm(e), 1e-8))
    return np.stack(out).astype(np.float32)


def _tally(rows: list[dict], key: str) -> dict:
    per: dict = {}
    for r in rows:
        p = per.setdefault(r["action"], {"n": 0, "strict": 0, "lenient": 0})
        p["n"] += 1
        p["strict"] += r[key] == r["action"]
        p["lenient"] += r[key] == r["action"] or r[key] in r["also"]
    n = sum(p["n"] for p in per.values())
    return {"accuracy": sum(p["strict"] for p in per.values()) / max(1, n),
            "accuracy_lenient": sum(p["lenient"] for p in per.values()) / max(1, n),
            "per_action": {a: {"n": p["n"], "accuracy": p["strict"] / p["n"], "accuracy_lenient": p["lenient"] / p["n"]}
                           for a, p in sorted(per.items())},
            "prompts": n}


def eval_paraphrase(model_dir=None, prompts=None, tma=None, seed: int = 0, seconds: float | None = 4.0,
                    progress=None, generator=None) -> dict:
    """Generate a motion per held-out prompt and classify it with the TMA (module docstring).
    Returns {"motion": {...}, "text": {...}, "unknown_action": [...], "actions": [...], "rows": [...]}."""
    from ..generation.generate import Generator, Request
    from ..generation.model_bundle import model_files
    from .tma_embed import embed_motions, embed_texts, load_tma

    items = load_prompts(prompts)
    gen = generator if generator is not None else Generator(model_dir)
    actions = gen.known_actions
    if not actions:
        raise ShapeMoveError(f"{gen.model_dir}: its T5 lists no known actions (trained before known_texts.json); "
                             "retrain it to evaluate paraphrases")
    if tma is None:
        tma = model_files(gen.model_dir)["tma"]
        if not Path(tma).is_file():
            raise ShapeMoveError(f"{gen.model_dir} has no tma/tma.pt: pass --tma PATH")
    tma = load_tma(tma) if isinstance(tma, (str, Path)) else tma
    model, tok, mean, std = tma
    A = action_embeddings(tma, actions)
    known = [it for it in items if it["action"] in actions]
    rows = []
    for i, it in enumerate(known):
        m = gen.generate_batch([Request(it["text"], seconds=seconds, seed=seed + i)])[0]
        motion_emb = embed_motions(model, [m.features], mean, std)[0]
        rows.append({**it, "motion_pred": actions[int(np.argmax(A @ motion_emb))],
                     "warned": bool(m.warnings)})
        if progress is not None:
            progress((i + 1) / len(known), it["text"])
    text_emb = embed_texts(model, tok, [r["text"] for r in rows]) if rows else np.zeros((0, A.shape[1]))
    for r, t in zip(rows, text_emb):
        r["text_pred"] = actions[int(np.argmax(A @ t))]
    return {"motion": _tally(rows, "motion_pred"), "text": _tally(rows, "text_pred"),
            "unknown_action": sorted({it["action"] for it in items if it["action"] not in actions}),
            "unknown_prompts": len(items) - len(known), "warned": sum(r["warned"] for r in rows),
            "actions": actions, "rows": rows}


def format_results(res: dict) -> str:
    m, t = res["motion"], res["text"]
    w = max([len(a) for a in m["per_action"]] + [6])
    lines = [f"Held-out paraphrases: {m['prompts']} prompts of {len(m['per_action'])} known actions "
             f"({res['unknown_prompts']} prompts of actions the model does not know: "
             f"{', '.join(res['unknown_action']) or 'none'})",
             f"{'action'.ljust(w)}  {'n':>3}  {'motion':>6}  {'text':>6}"]
    for a, p in m["per_action"].items():
        lines.append(f"{a.ljust(w)}  {p['n']:>3}  {100 * p['accuracy']:>5.0f}%  {100 * t['per_action'][a]['accuracy']:>5.0f}%")
    lines.append(f"{'overall'.ljust(w)}  {m['prompts']:>3}  {100 * m['accuracy']:>5.1f}%  {100 * t['accuracy']:>5.1f}%")
    lines.append(f"lenient (an 'also' action counts): motion {100 * m['accuracy_lenient']:.1f}%, "
                 f"text {100 * t['accuracy_lenient']:.1f}%; prompts warned as far from the training data: "
                 f"{res['warned']}")
    return "\n".join(lines)


def add_arguments(p) -> None:
    """Options of `python -m shapemove eval paraphrase`."""
    p.add_argument("--model", type=Path, default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--prompts", type=Path, default=None, help="held-out prompts (default configs/heldout_paraphrases.json)")
    p.add_argument("--tma", type=Path, default=None, help="TMA classifier (default: the model's tma/)")
    p.add_argument("--seconds", type=float, default=4.0, help="length of each generated motion")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", type=Path, default=None, help="write the results here")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def from_cli(args) -> int:
    from tqdm import tqdm

    bar = tqdm(total=100, desc="eval paraphrase", unit="%", disable=args.quiet)

    def progress(frac, msg):
        bar.update(round(100 * frac) - bar.n)

    try:
        res = eval_paraphrase(args.model, args.prompts, args.tma, args.seed, args.seconds, progress)
    finally:
        bar.close()
    print(format_results(res))
    if args.json:
        print(f"wrote {atomic_write_json(args.json, res, nan_to_null=True)}")
    return 0
