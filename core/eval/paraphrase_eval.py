"""Held-out paraphrase evaluation: does a prompt in words the captions never used give the right action?

    res = eval_paraphrase("weights/default", data="data/built")   # configs/heldout_paraphrases.json
    res["motion"]["accuracy"], res["motion"]["per_action"]["walk"], res["classifier"]["ceiling"]["accuracy"]

For each held-out prompt ({"text", "action", "also"?}, written by hand, never trained or tuned on)
the model generates a motion, and its action is read three ways, each from the features of what the
rig plays (``motion_features`` of the planted Motion, computed as the dataset builder computes a
clip's, not the decoded features, whose rotations the rig does not play):

- ``motion`` (the target: >= 80 % right): the generated motion's TMA motion embedding among the
  training clips' motion embeddings of the built dataset ``data``: the majority action of its 5
  nearest clips (``core/eval/action_classifier.py``). ``classifier.ceiling``: how often that
  classifier names the action of the REAL clips of the test split (the most a generator can get);
- ``text``: the prompt's own TMA text embedding against one text prototype per action the model
  knows (the mean of the TMA's unit embeddings of "A person {phrase}." over the action's caption
  phrases, ``core/data/actions.py``), nearest wins: how well the text side reads the paraphrase,
  independent of the generator;
- ``motion_vs_text_prototypes``: the generated motion's embedding against those same text
  prototypes (the classifier used before; weak even on real clips, reported so nothing is hidden);
- ``motion_features``: the same 5-NN vote on an embedding without the TMA
  (``action_classifier.FeatureEmbedder``): generation keeps the best of several samples by TMA
  similarity (``generation/rerank.py``), and this judge cannot be flattered by that choice.

``reachable`` is what a perfect generator could score on these prompts under each classifier: the
mean over the prompts of their action's leave-one-take-out accuracy on the training clips
(``ActionClassifier.reachable``; 0 for an action that is no clip's main action).

``seed`` may be several seeds: every prompt is generated once per seed (prompt i on seed ``s + i``,
as a single seed does) and each generation counts as one row, so the accuracies are the sums over
the seeds; one seed moves a 150-prompt set by about 5 prompts (docs/evaluation.md), so compare
models on two or more.

Each strict (the expected action) and lenient (also one of "also"), per action and overall, over
the prompts whose action the model was trained on; prompts of actions it does not know are
counted apart (``unknown_action``). The TMA was trained on the training captions only, so it
was not tuned on these prompts either.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError

DEFAULT_PROMPTS = Path(__file__).resolve().parents[2] / "configs" / "heldout_paraphrases.json"
MAX_PROMPTS_BYTES = 4 << 20


def load_prompts(path=None) -> list[dict]:
    """The held-out prompts [{text, action, also: [..]}] of a JSON file ({"prompts": [...]} or a list)."""
    from .report import prompt_items

    path, items = prompt_items(path, DEFAULT_PROMPTS, "paraphrase prompt list", MAX_PROMPTS_BYTES)
    out = []
    for i, it in enumerate(items):
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


def _tally(rows: list[dict], key: str, pairs: set | None = None) -> dict:
    """Strict, lenient (an 'also' action counts) and, with ``pairs``, merged (a pair the judge does not
    tell apart in real performances counts, ``indistinct_actions.py``) accuracy, overall and per action."""
    from .indistinct_actions import merged_right

    per: dict = {}
    for r in rows:
        p = per.setdefault(r["action"], {"n": 0, "strict": 0, "lenient": 0, "merged": 0})
        p["n"] += 1
        p["strict"] += r[key] == r["action"]
        p["lenient"] += r[key] == r["action"] or r[key] in r["also"]
        p["merged"] += merged_right(r["action"], r[key], pairs or set())
    n = sum(p["n"] for p in per.values())
    out = {"accuracy": sum(p["strict"] for p in per.values()) / max(1, n),
           "accuracy_lenient": sum(p["lenient"] for p in per.values()) / max(1, n),
           "per_action": {a: {"n": p["n"], "accuracy": p["strict"] / p["n"], "accuracy_lenient": p["lenient"] / p["n"],
                              **({"accuracy_merged": p["merged"] / p["n"]} if pairs is not None else {})}
                          for a, p in sorted(per.items())},
           "prompts": n}
    if pairs is not None:
        out["accuracy_merged"] = sum(p["merged"] for p in per.values()) / max(1, n)
    return out


def eval_paraphrase(model_dir=None, prompts=None, tma=None, seed: int | list[int] = 0, seconds: float | None = 4.0,
                    progress=None, generator=None, data=None, classifier=None, ceiling_clips: int | None = None,
                    show_progress: bool = True, candidates: int | None = None, feature_classifier=None,
                    retrieval: bool = True, frequent: int = 20, retrieval_prefix: int | None = None,
                    retrieved: int | None = None, retrieval_first: float | None = None, by_parts: bool = True,
                    library=None, captured: bool = True) -> dict:
    """Generate a motion per held-out prompt and classify it (module docstring). ``data``: the built
    dataset whose training clips the kNN classifier reads (default ``default_built_dir()``);
    ``classifier``: an ``ActionClassifier`` to use instead (``feature_classifier`` likewise for the
    TMA-free one); ``candidates``: best-of-N samples per prompt (default: the product's);
    ``retrieval_prefix``: codes of a retrieved clip the seeded candidates start from (default: the
    product's; 0 none, ``retrieval_seeds.py``); ``library``: a folder of captioned motions added to the
    memory first, as a user's Library (``Generator.add_library``); ``captured``: captured takes compete
    (the product's default; ``Generator.set_captured``). Returns
    {"motion", "text", "motion_vs_text_prototypes", "motion_features", "reachable", "classifier",
    "unknown_action", "actions", "rows", ...}."""
    from ..generation.generate import Generator, Request
    from ..generation.model_bundle import model_files
    from ..motion.features import motion_features
    from ..generation.sampling_params import or_defaults
    from .action_classifier import ActionClassifier, built_dir
    from .action_signatures import signatures, signed
    from .tma_embed import embed_motions, embed_texts, load_tma

    items = load_prompts(prompts)
    seeds = [int(seed)] if isinstance(seed, (int, np.integer)) else [int(s) for s in seed]
    if not seeds or len(set(seeds)) != len(seeds):
        raise ShapeMoveError(f"eval paraphrase needs one or more distinct seeds, got {list(seeds)}")
    candidates, retrieved, retrieval_first, retrieval_prefix = or_defaults(candidates, retrieved, retrieval_first,
                                                                           retrieval_prefix)
    if classifier is None:
        data = built_dir(data, "eval paraphrase classifies generated motions by their nearest training clips")
    gen = generator if generator is not None else Generator(model_dir)
    gen.set_retrieval(retrieval)
    gen.set_captured(captured)
    if library is not None:
        gen.add_library(library)
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
    if classifier is None:
        classifier = ActionClassifier.from_data(tma, data, actions, progress=show_progress)
        ceiling = classifier.ceiling(data, "test", max_clips=ceiling_clips, progress=show_progress)
    else:
        ceiling = classifier.ceiling(data, "test", max_clips=ceiling_clips, progress=show_progress) if data else None
    if feature_classifier is None and data is not None:
        feature_classifier = ActionClassifier.from_features(data, actions, progress=show_progress)
    A = action_embeddings(tma, actions)
    known = [it for it in items if it["action"] in actions]
    rows, embs, feats = [], [], []
    runs = [(s, i, it) for s in seeds for i, it in enumerate(known)]
    for n, (s, i, it) in enumerate(runs):
        m = gen.generate_batch([Request(it["text"], seconds=seconds, seed=s + i, candidates=candidates,
                                        retrieval_prefix=retrieval_prefix, retrieved=retrieved if retrieval else 0,
                                        retrieval_first=retrieval_first, by_parts=by_parts)])[0]
        played = motion_features(m)   # what the rig plays (a plain prompt's decoded features differ)
        motion_emb = embed_motions(model, [played], mean, std)[0]
        embs.append(motion_emb)
        feats.append(played)
        sig = signed(it["action"])   # a third judge where the action has a physical signature
        rows.append({**it, "seed": s, "seconds": round(m.num_frames / m.fps, 2),
                     "signature_right": None if sig is None else bool(signatures(m.joints)[sig]),
                     "motion_proto_pred": actions[int(np.argmax(A @ motion_emb))],
                     "warned": bool(m.warnings), "kept_clips": list(m.retrieved_clips),
                     "parts": list(m.part_prompts) if m.part_prompts else None,
                     "mirrored": bool(m.mirrored or m.arms_mirrored)})
        if progress is not None:
            progress((n + 1) / len(runs), it["text"])
    kept = [r["kept_clips"] for r in rows]  # retrieved clips are judged without their own takes
    for r, p in zip(rows, classifier.classify_embeddings(np.stack(embs), exclude=kept) if embs else []):
        r["motion_pred"] = p
    if feature_classifier is not None:
        for r, p in zip(rows, feature_classifier.classify(feats, exclude=kept)):
            r["motion_features_pred"] = p
    text_emb = embed_texts(model, tok, [r["text"] for r in rows]) if rows else np.zeros((0, A.shape[1]))
    for r, t in zip(rows, text_emb):
        r["text_pred"] = actions[int(np.argmax(A @ t))]
    nearest = nearest_caption_baseline(classifier, data, rows, gen) if data is not None and rows else None
    counts: dict = {}
    for a in classifier.labels:
        counts[a] = counts.get(a, 0) + 1
    often = [r for r in rows if counts.get(r["action"], 0) >= frequent]
    clfs = {"motion": classifier, "motion_features": feature_classifier}
    per_action = {k: c.reachable() for k, c in clfs.items() if c is not None}   # one leave-one-take-out pass each
    reach = {k: _reachable(per, rows) for k, per in per_action.items()}
    merged = _indistinct(clfs, data, seconds)
    pairs = {k: set(map(frozenset, v)) for k, v in merged["pairs"].items()}
    return {"motion": _tally(rows, "motion_pred", pairs.get("motion")), "text": _tally(rows, "text_pred"),
            "motion_vs_text_prototypes": _tally(rows, "motion_proto_pred"),
            **({"motion_features": _tally(rows, "motion_features_pred", pairs.get("motion_features"))}
               if feature_classifier is not None else {}),
            "reachable": reach, "indistinct": merged, "signature": _signature_tally(rows, pairs.get("motion")),
            **({"nearest_caption": _tally(rows, "nearest_caption_pred")} if nearest else {}),
            "frequent": {"min_clips": frequent, "actions": sorted({r["action"] for r in often}),
                         "motion": _tally(often, "motion_pred", pairs.get("motion")),
                         **({"motion_features": _tally(often, "motion_features_pred", pairs.get("motion_features"))}
                            if feature_classifier is not None else {}),
                         "reachable": {k: _reachable(per, often) for k, per in per_action.items()},
                         **({"nearest_caption": _tally(often, "nearest_caption_pred")} if nearest else {})},
            "retrieval": bool(retrieval and gen.reads_memory),
            "candidates": candidates,
            "retrieval_prefix": retrieval_prefix if retrieval and gen.reads_memory else 0,
            "retrieved": retrieved if retrieval else 0, "retrieval_first": retrieval_first,
            "kept_retrieved": sum(bool(r["kept_clips"]) for r in rows), "by_parts": by_parts, "seeds": seeds,
            "seconds": seconds,
            "library": str(library) if library is not None else None,
            "kept_library": sum(any(str(c).startswith("library:") for c in r["kept_clips"]) for r in rows),
            "composed": sum(bool(r["parts"]) for r in rows), "mirrored": sum(r["mirrored"] for r in rows),
            "classifier": {**classifier.info, "ceiling": ceiling},
            "feature_classifier": dict(feature_classifier.info) if feature_classifier is not None else None,
            "unknown_action": sorted({it["action"] for it in items if it["action"] not in actions}),
            "unknown_prompts": len(items) - len(known), "warned": sum(r["warned"] for r in rows),
            "prompts_file": str(Path(prompts) if prompts else DEFAULT_PROMPTS),
            "actions": actions, "rows": rows}


def _signature_tally(rows: list[dict], pairs: set | None) -> dict:
    """The prompts whose action has a physical signature (``action_signatures.py``): how often the
    played motion shows it, per action, beside the TMA judge's merged reading of the same prompts."""
    from .indistinct_actions import merged_right

    signed_rows = [r for r in rows if r.get("signature_right") is not None]
    per: dict = {}
    for r in signed_rows:
        p = per.setdefault(r["action"], {"n": 0, "right": 0, "motion_merged": 0})
        p["n"] += 1
        p["right"] += r["signature_right"]
        p["motion_merged"] += bool(r.get("motion_pred") and merged_right(r["action"], r["motion_pred"], pairs or set()))
    n = len(signed_rows)
    return {"prompts": n, "accuracy": sum(p["right"] for p in per.values()) / n if n else None,
            "motion_merged": sum(p["motion_merged"] for p in per.values()) / n if n else None,
            "per_action": {a: {**p, "accuracy": p["right"] / p["n"], "motion_merged": p["motion_merged"] / p["n"]}
                           for a, p in sorted(per.items())}}


def _indistinct(clfs: dict, data, seconds: float | None) -> dict:
    """Per judge, the pairs of actions whose real windows of the played length it does not tell apart,
    their windows' confusion, the takes per action and each action's real windows named right with
    those pairs merged (``windows_right``: what a real performance of that length is credited with)
    (``indistinct_actions.py``)."""
    from ..constants import FPS
    from .indistinct_actions import indistinct_pairs, take_counts, window_accuracy, window_confusion

    frames = int(round((seconds or 4.0) * FPS))   # the model's own length: the evaluation's 4 s
    out: dict = {"frames": frames, "pairs": {}, "confusion": {}, "takes": {}, "windows_right": {}}
    for k, c in clfs.items():
        if c is None or data is None:
            continue
        conf, takes = window_confusion(c, data, frames), take_counts(c)
        pairs = indistinct_pairs(conf, takes)
        out["pairs"][k] = sorted(sorted(p) for p in pairs)
        out["confusion"][k], out["takes"][k] = conf, takes
        out["windows_right"][k] = window_accuracy(conf, pairs)
    return out


def nearest_caption_baseline(classifier, data, rows: list[dict], gen) -> bool:
    """No generation at all: copy the real training clip (a reference of ``classifier``) whose
    caption is nearest to the prompt by MiniLM cosine, and judge it among the other references
    without its own source. Sets ``row["nearest_caption_pred"]``; False when it cannot run."""
    from ..models.motion_memory import sentence_vectors

    ids = getattr(classifier, "ids", None)
    if not ids:
        return False
    caps, owner = [], []
    for i, cid in enumerate(ids):
        path = Path(data) / "texts" / f"{cid}.txt"
        for c in (path.read_text(encoding="utf-8").splitlines() if path.is_file() else []):
            if c.strip():
                caps.append(c.strip())
                owner.append(i)
    if not caps:
        return False
    reader = gen._text_encoder()
    V = sentence_vectors(reader, caps)
    Q = sentence_vectors(reader, [r["text"] for r in rows])
    best = [owner[int(j)] for j in (Q @ V.T).argmax(1)]
    for r, p in zip(rows, classifier.classify_references(best)):
        r["nearest_caption_pred"] = p
    return True


def _reachable(per_action: dict, rows: list[dict]) -> float | None:
    """Mean over the prompts of their action's leave-one-take-out accuracy (``ActionClassifier.reachable``
    as ``per_action``; 0 without clips)."""
    if not rows:
        return None
    return float(np.mean([per_action.get(r["action"], {}).get("accuracy", 0.0) for r in rows]))


def _pct(v, digits: int = 1) -> str:
    return "—" if v is None else f"{100 * v:.{digits}f}%"


def format_results(res: dict) -> str:
    m, t, pr = res["motion"], res["text"], res["motion_vs_text_prototypes"]
    ceil = (res.get("classifier") or {}).get("ceiling") or {}
    real = ceil.get("per_action") or {}
    w = max([len(a) for a in m["per_action"]] + [7])
    seeds = res.get("seeds") or [0]
    lines = [f"Held-out paraphrases ({Path(res.get('prompts_file', '')).name}): {m['prompts'] // len(seeds)} prompts of "
             f"{len(m['per_action'])} known actions ({res['unknown_prompts']} prompts of actions the model does "
             f"not know: {', '.join(res['unknown_action']) or 'none'})"
             + (f"; each generated on {len(seeds)} seeds ({', '.join(map(str, seeds))}), every column counts "
                f"{m['prompts']} generations" if len(seeds) > 1 else ""),
             "motion: generated motion, 5 nearest training clips in TMA motion space; real: the same classifier "
             "on real test clips of the action; text: the prompt's TMA text vs action text prototypes; "
             "m-vs-t: generated motion vs those text prototypes",
             f"{'action'.ljust(w)}  {'n':>3}  {'motion':>6}  {'real':>6}  {'text':>6}  {'m-vs-t':>6}"]
    for a, p in m["per_action"].items():
        r = real.get(a)
        lines.append(f"{a.ljust(w)}  {p['n']:>3}  {_pct(p['accuracy'], 0):>6}  "
                     f"{_pct(r['accuracy'], 0) if r else '—':>6}  {_pct(t['per_action'][a]['accuracy'], 0):>6}  "
                     f"{_pct(pr['per_action'][a]['accuracy'], 0):>6}")
    lines.append(f"{'overall'.ljust(w)}  {m['prompts']:>3}  {_pct(m['accuracy']):>6}  {_pct(ceil.get('accuracy')):>6}  "
                 f"{_pct(t['accuracy']):>6}  {_pct(pr['accuracy']):>6}")
    lines.append(f"lenient (an 'also' action counts): motion {_pct(m['accuracy_lenient'])}, text "
                 f"{_pct(t['accuracy_lenient'])}, motion vs text prototypes {_pct(pr['accuracy_lenient'])}; "
                 f"prompts warned as far from the training data: {res['warned']}")
    if res.get("motion_features"):
        lines.append(f"without the TMA (5-NN on pooled raw features): motion {_pct(res['motion_features']['accuracy'])} "
                     f"({_pct(res['motion_features']['accuracy_lenient'])} lenient)")
    lines += _merged_lines(res)
    sig = res.get("signature") or {}
    if sig.get("prompts"):
        lines.append(f"physical signatures (a flight, a dip, a raised wrist swinging...: eval/action_signatures.py) "
                     f"on the {sig['prompts']} prompts of an action that has one: shown {_pct(sig['accuracy'])}, the "
                     f"TMA judge merged {_pct(sig['motion_merged'])}; "
                     + ", ".join(f"{a} {_pct(p['accuracy'], 0)} / {_pct(p['motion_merged'], 0)}"
                                 for a, p in sig["per_action"].items()))
    reach = res.get("reachable") or {}
    if reach:
        lines.append("reachable (a perfect generator, each prompt's action judged by leave-one-take-out on the "
                     "training clips): " + ", ".join(f"{k} {_pct(v)}" for k, v in reach.items()))
    if res.get("nearest_caption"):
        lines.append(f"no generation, the real clip with the nearest caption (MiniLM) copied and judged the same "
                     f"way: {_pct(res['nearest_caption']['accuracy'])} ({_pct(res['nearest_caption']['accuracy_lenient'])} lenient)")
    fr = res.get("frequent") or {}
    if fr.get("motion"):
        lines.append(f"actions with >= {fr['min_clips']} real training clips ({fr['motion']['prompts']} prompts): motion "
                     f"{_pct(fr['motion']['accuracy'])} ({_pct(fr['motion']['accuracy_lenient'])} lenient)"
                     + (f", without the TMA {_pct(fr['motion_features']['accuracy'])}" if fr.get("motion_features") else "")
                     + (f", nearest caption {_pct(fr['nearest_caption']['accuracy'])}" if fr.get("nearest_caption") else "")
                     + (", reachable " + ", ".join(f"{k} {_pct(v)}" for k, v in fr["reachable"].items())
                        if fr.get("reachable") else ""))
    lines.append(f"retrieved clips read by the decoder: {'yes' if res.get('retrieval') else 'no'}; real clips "
                 f"retrieved as candidates: {res.get('retrieved', 0)} per prompt"
                 + (f", alone from caption similarity {res['retrieval_first']:g}" if res.get("retrieval_first") else "")
                 + f"; kept a retrieved clip for {res.get('kept_retrieved', 0)} prompts (judged without its own take)")
    secs = res.get("seconds", 4.0)
    lines.append("length: " + (f"{secs:g} s each" if secs is not None else
                               "the model's choice (the product's default when no length is set)"))
    lines.append(f"by body part: {'on' if res.get('by_parts', True) else 'off'}; two things composed for "
                 f"{res.get('composed', 0)} prompts, mirrored to a named side for {res.get('mirrored', 0)}")
    seeded = res.get("retrieval_prefix") or 0
    lines.append(f"best of {res.get('candidates', 1)} samples per prompt (TMA choice)"
                 + (f", half of them continuing the first {seeded} codes of a retrieved clip" if seeded else ""))
    if ceil:
        info = res["classifier"]
        lines.append(f"the classifier ({info.get('k')}-NN over {info.get('clips')} {info.get('split')} clips) names real "
                     f"{ceil['split']} clips' action {_pct(ceil['accuracy'])} of the time "
                     f"({_pct(ceil['accuracy_lenient'])} lenient: any of the clip's actions; {ceil['clips']} clips)")
    return "\n".join(lines)


def _merged_lines(res: dict, min_takes: int = 3, bar: float = 0.6) -> list[str]:
    """The merged figures of each judge (pairs it does not tell apart in real windows counted right)
    and the actions with at least ``min_takes`` takes under ``bar`` by either judge."""
    ind = res.get("indistinct") or {}
    fr = res.get("frequent") or {}
    lines = []
    for k, name in (("motion", "TMA judge"), ("motion_features", "raw-feature judge")):
        t = res.get(k) or {}
        if "accuracy_merged" not in t:
            continue
        pairs = ind.get("pairs", {}).get(k) or []
        often = (fr.get(k) or {}).get("accuracy_merged")
        lines.append(f"merged, {name} (real {ind.get('frames', 80)}-frame windows not told apart: "
                     f"{'; '.join(' / '.join(p) for p in pairs) or 'none'}): {_pct(t['accuracy_merged'])}"
                     + (f", actions with >= {fr.get('min_clips')} clips {_pct(often)}" if often is not None else ""))
        takes = ind.get("takes", {}).get(k) or {}
        low = [f"{a} {_pct(p['accuracy_merged'], 0)}" for a, p in t["per_action"].items()
               if takes.get(a, 0) >= min_takes and p["accuracy_merged"] < bar]
        lines.append(f"  actions with >= {min_takes} takes under {_pct(bar, 0)} ({name}, merged): {', '.join(low) or 'none'}")
    return lines


def add_arguments(p) -> None:
    """Options of `python -m shapemove eval paraphrase`."""
    from .report import add_output_arguments

    p.add_argument("--model", type=Path, default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--prompts", type=Path, default=None, help="held-out prompts (default configs/heldout_paraphrases.json)")
    p.add_argument("--data", type=Path, default=None,
                   help="built dataset the model was trained on: its training clips classify the generated motions "
                        "(default $SHAPEMOVE_BUILT, else data/built)")
    p.add_argument("--tma", type=Path, default=None, help="TMA whose embeddings are compared (default: the model's tma/)")
    p.add_argument("--seconds", type=float, default=4.0, help="length of each generated motion")
    p.add_argument("--model-length", action="store_true",
                   help="the model decides each motion's length, as the product does when no length is set "
                        "(instead of --seconds)")
    p.add_argument("--seed", type=int, nargs="+", default=[0], metavar="SEED",
                   help="one or more seeds: each prompt is generated once per seed and the accuracies sum them "
                        "(one seed moves a 150-prompt set by about 5 prompts: compare models on two or more)")
    p.add_argument("--candidates", type=int, default=None,
                   help="token samples per prompt, the TMA keeps the closest (default: the product's, 8; 1 = none)")
    add_output_arguments(p)
    p.add_argument("--no-retrieval", action="store_true", help="the decoder reads no retrieved clips (to compare)")
    p.add_argument("--retrieval-prefix", type=int, default=None, metavar="CODES",
                   help="codes of a retrieved clip half the candidates start from (default: the product's; 0: none)")
    p.add_argument("--retrieved", type=int, default=None, metavar="CLIPS",
                   help="real clips nearest by caption added to the candidates (default: the product's; 0: none)")
    p.add_argument("--retrieval-first", type=float, default=None, metavar="SIM",
                   help="caption similarity from which only retrieved clips compete (default: the product's)")
    p.add_argument("--library", type=Path, default=None, metavar="DIR",
                   help="a folder of captioned motions added to the memory, as the panel's Library "
                        "(a kept clip of it is judged as what the rig plays)")
    p.add_argument("--no-library", action="store_true",
                   help="no captured take competes (generation only, as `generate --no-library`)")
    p.add_argument("--no-parts", action="store_true",
                   help="generate each prompt whole: no composition by body part, no mirroring to a named side")


def from_cli(args) -> int:
    from .report import run_and_show

    seconds = None if args.model_length else args.seconds
    # the bar opens at the first prompt, after the classifier's bars
    return run_and_show("eval paraphrase", args.quiet, lambda progress: eval_paraphrase(
        args.model, args.prompts, args.tma, args.seed, seconds, progress, data=args.data,
        show_progress=not args.quiet, candidates=args.candidates, retrieval=not args.no_retrieval,
        retrieval_prefix=args.retrieval_prefix, retrieved=args.retrieved, retrieval_first=args.retrieval_first,
        by_parts=not args.no_parts, library=args.library, captured=not args.no_library), format_results, args.json)
