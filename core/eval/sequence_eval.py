"""Held-out one-prompt sequences: is each segment of "X, then Y" made, and in its order?

    res = eval_sequences("weights/default", data="data/built")   # configs/heldout_sequences.json
    res["segments"]["accuracy"], res["order"]["accuracy"], res["split"]["accuracy"]

Each held-out prompt ([text, [a word each segment must hold, in the order they happen]], written
by hand and never used to tune ``core/plan/segments.py``) is read into its plan
(``core/plan/plan.read_plan``) and generated as the product generates it (``generate --prompt``:
``Generator.generate_batch``; a plan of several segments becomes a timeline of them,
``Generator.planned_sequence``, each ``SEGMENT_SECONDS`` long unless ``seconds`` shares a total).
The played motion (``motion_features`` of the planted Motion) is cut at the segment bounds the
motion records (``Motion.segment_bounds``) and each piece judged by a judge that does not use the
TMA the generator picks its samples with (``generation/rerank.py``):

- a gait of ``compose_parts.LEGS_ACTIONS`` by the part judge's legs (``part_judge.legs_right``:
  "walk in a circle" must circle), a gesture (of ``ARMS_ACTIONS``, in the vocabulary's "gesture"
  group: a wave, a raised hand) by its arms (``arms_right``);
- an action with a physical signature (``action_signatures.py``: a jump and its forms, a squat,
  lying down, getting up, a spin, a kick, jumping jacks, a wave) by it, on the piece's joints, before
  either judge above: the vote below names real captured jumps, get-ups and spins 0 % of the time,
  the arms read 3 s of a captured two-handed wave as a raised hand; the signatures pass 71-100 % of
  the real clips of their action and 0-1.2 % of the others' (``signature_accuracy.py``,
  ``tools/signature_check.py``, 3 s windows);
- any other action by the 5-NN vote among the training clips on pooled raw features
  (``ActionClassifier.from_features``, as ``paraphrase_eval`` reads ``motion_features``).

The figures without the signatures (each such action by the judge above that reads it otherwise: a
wave by the arms, a jump by the vote) are reported beside them (``segments_vote``, ``order_vote``).

A segment's expected action is the data's action vocabulary (``core/data/actions.action_spans``)
at the segment's word in the prompt ('strolls' -> walk, 'takes a bow' -> bow, 'stands up' -> get
up); a word no action of the vocabulary covers ('takes a seat', 'salutes', 'nods'), or an action
neither judge can name (no reference clips of it), leaves the segment unjudged, counted apart.

Reported: ``segments`` (judged segments right, per expected action; ``accuracy_lenient`` also
counts a specific form of the action, ``actions.GENERIC_OF``: a jump forward for a jump),
``reachable`` (what copying real performances could score: each action's judge on the real
training clips of it, each without its own take, ``reachable``),
``all_right`` (prompts of judged segments only, every one right), ``split`` (the plan has as many
segments as expected, each holding its word: ``split_right``), ``order`` (the plan's segments hold
the words in the expected order, and the motion shows them in that order: for every two segments,
neighbours or not, of different judged actions, the judges find more of the two actions where they
belong than swapped, ``motion_order``; ``order_not_reversed``: no fewer). A prompt the plan does
not cut into the expected number of segments has no segment to judge: each of its judged segments
counts as wrong and its order as wrong.
Target (issue #54): segments >= 80 %, order >= 95 %.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError

DEFAULT_PROMPTS = Path(__file__).resolve().parents[2] / "configs" / "heldout_sequences.json"
MAX_PROMPTS_BYTES = 1 << 20
TARGETS = {"segments": 0.80, "order": 0.95}
LEGS, ARMS, SIGNATURE, ACTION = "legs", "arms", "signature", "action"   # which judge reads an action


def load_sequences(path=None) -> list[dict]:
    """The held-out sequences [{text, words}] of a JSON file ({"prompts": [[text, [word, ...]], ...]})."""
    from .report import prompt_items

    path, items = prompt_items(path, DEFAULT_PROMPTS, "sequence prompt list", MAX_PROMPTS_BYTES)
    out = []
    for i, it in enumerate(items):
        if not (isinstance(it, list) and len(it) == 2 and isinstance(it[0], str) and it[0].strip()
                and isinstance(it[1], list) and it[1] and all(isinstance(w, str) and w.strip() for w in it[1])):
            raise ShapeMoveError(f"{path}: prompt {i} must be [\"text\", [\"a word of each segment\", ...]]")
        out.append({"text": it[0], "words": [w.strip().lower() for w in it[1]]})
    if not out:
        raise ShapeMoveError(f"{path}: no prompts (expected {{\"prompts\": [[text, [word, ...]], ...]}})")
    return out


def expected_actions(text: str, words: list[str]) -> list[str | None]:
    """Each segment word's canonical action: the action the vocabulary finds over that word where it
    stands in ``text`` (its first place no earlier word took: the words are in the order things
    happen, not always the prompt's, "before kicking the ball, he jogs"; a word may be the start of
    a longer one: 'wav' of 'waving'); None when no action covers it."""
    from ..data.actions import action_spans, split_words

    t = split_words(text)
    spans = action_spans(text)
    out, taken = [], set()
    for w in words:
        w = split_words(w)
        start = next((i for i in _word_starts(t, w) if i not in taken), None)
        if start is None:
            out.append(None)
            continue
        taken.add(start)
        hit = [name for s, e, name in spans if s < start + len(w) and e > start]
        out.append(hit[0] if hit else None)
    return out


def _word_starts(text: str, word: str):
    """Where ``word`` starts a word of ``text`` (a prefix of it: 'wav' of 'waving'), in order."""
    i = text.find(word)
    while word and i >= 0:
        if i == 0 or not text[i - 1].isalnum():
            yield i
        i = text.find(word, i + 1)


def split_right(segments: list[str], words: list[str]) -> bool:
    """The plan cut the prompt as expected: as many segments as words, each holding its word, in order."""
    return len(segments) == len(words) and all(w in s.lower() for w, s in zip(words, segments))


def judge_of(action: str | None, judge, classifier, signatures: bool = True) -> str | None:
    """Which judge reads ``action``: ``LEGS`` (a gait of ``LEGS_ACTIONS`` the part judge knows),
    ``ARMS`` (a gesture: an action of ``ARMS_ACTIONS`` in the vocabulary's "gesture" group that it
    knows; a punch or a throw moves the whole body), ``ACTION`` (the raw-feature classifier has
    clips of it), None (none can name it); before them all ``SIGNATURE``, an action with a physical
    signature (``action_signatures.signed``: a wave too), unless ``signatures`` is False."""
    from ..data.actions import ACTIONS
    from ..data.compose_parts import ARMS_ACTIONS, LEGS_ACTIONS
    from .action_signatures import signed
    from .part_judge import CIRCLE, SAME_MOTION

    if action is None:
        return None
    if signatures and signed(action) is not None:
        return SIGNATURE
    if action in LEGS_ACTIONS and ("walk" if action == CIRCLE else action) in judge.legs.classes:
        return LEGS
    if action in ARMS_ACTIONS and ACTIONS[action].group == "gesture" and \
            SAME_MOTION.get(action, action) in judge.arms.classes:
        return ARMS
    return ACTION if classifier is not None and action in set(classifier.labels) else None


def shows(action: str, kind: str | None, reading: dict | None, lenient: bool = False) -> bool | None:
    """Whether a segment's ``reading`` ({"legs", "path", "arms", "action", "signatures"}) shows
    ``action`` by the judge ``kind`` (``judge_of``); None when it cannot be told. ``lenient``: a
    specific form of the action counts too (``actions.GENERIC_OF``: a jump forward for a jump, a
    sneak for a walk; a signature reads a jump's forms alike)."""
    from ..data.actions import GENERIC_OF
    from .action_signatures import signed
    from .part_judge import arms_right, legs_right

    if kind is None or reading is None:
        return None
    if kind == SIGNATURE:
        return bool(reading["signatures"][signed(action)])
    right = legs_right(action, reading) if kind == LEGS else \
        arms_right(action, reading) if kind == ARMS else reading["action"] == action
    return right or (lenient and action in GENERIC_OF.get(reading[kind], ()))


def read_segments(features, bounds, judge, classifier, exclude=None) -> list[dict | None]:
    """Each segment [start, end) of the played (T-1, 263) ``features`` judged by the part judge, the
    classifier and the signatures: {"legs", "path", "arms", "action", "signatures", "frames"}, None
    for a piece too short to judge. ``exclude``: training clips the motion was made from (judged
    without their takes)."""
    from ..motion.features import joints_from_features
    from .action_signatures import signatures
    from .part_judge import MIN_FRAMES

    f = np.asarray(features)
    pieces = [f[int(s):min(int(e), len(f))] for s, e in np.asarray(bounds)]
    ok = [i for i, p in enumerate(pieces) if len(p) >= MIN_FRAMES]
    parts = judge.judge([pieces[i] for i in ok], [exclude or None] * len(ok)) if ok else []
    acts = classifier.classify([pieces[i] for i in ok], exclude=[exclude or None] * len(ok)) \
        if ok and classifier is not None else [None] * len(ok)
    out: list[dict | None] = [None] * len(pieces)
    for i, p, a in zip(ok, parts, acts):
        out[i] = {"legs": p["legs"], "path": p["path"], "arms": p["arms"], "action": a,
                  "signatures": signatures(joints_from_features(np.asarray(pieces[i], np.float32))),
                  "frames": len(pieces[i])}
    return out


def motion_order(actions: list[str | None], kinds: list[str | None], readings: list[dict | None]) -> list[list[int]]:
    """How the motion orders its segments' actions: for every two segments i < j of different judged
    actions a, b, [i, j, segments of the two showing a in i and b in j, showing b in i and a in j];
    in order when every pair shows more in order than swapped (``in_order``)."""
    pairs = []
    for i in range(len(actions)):
        for j in range(i + 1, len(actions)):
            a, b = actions[i], actions[j]
            if a is None or b is None or a == b or kinds[i] is None or kinds[j] is None:
                continue
            ordered = [shows(a, kinds[i], readings[i]), shows(b, kinds[j], readings[j])]
            swapped = [shows(b, kinds[j], readings[i]), shows(a, kinds[i], readings[j])]
            if None not in ordered + swapped:
                pairs.append([i, j, sum(ordered), sum(swapped)])
    return pairs


def in_order(pairs: list[list[int]], strict: bool = True) -> bool | None:
    """``motion_order``'s pairs all shown more in order than swapped (``strict``; else: none shown more
    swapped than in order); None without a pair."""
    if not pairs:
        return None
    return all(o > w if strict else o >= w for _, _, o, w in pairs)


def judge_prompt(item: dict, segments: list[str], features, bounds, judge, classifier, exclude=None) -> dict:
    """One generated prompt judged (module docstring): ``segments`` the plan's segment texts,
    ``features`` the played motion's, ``bounds`` its recorded (S, 2) segment frames (None: one)."""
    words = item["words"]
    actions = expected_actions(item["text"], words)
    kinds = [judge_of(a, judge, classifier) for a in actions]
    votes = [judge_of(a, judge, classifier, signatures=False) for a in actions]   # the figures without them
    cut = bounds is not None and len(bounds) == len(words)
    readings = read_segments(features, bounds, judge, classifier, exclude) if cut else [None] * len(words)
    split = split_right(segments, words)

    def judged(ks):
        right = [shows(a, k, r) if cut else (False if k is not None else None) for a, k, r in zip(actions, ks, readings)]
        lenient = [shows(a, k, r, lenient=True) if cut else ok for a, k, r, ok in zip(actions, ks, readings, right)]
        pairs = motion_order(actions, ks, readings) if cut else []

        def order(strict: bool):
            moved = in_order(pairs, strict)
            return (split and moved) if moved is not None else (False if not split else None)

        return right, lenient, pairs, order(True), order(False)

    right, lenient, pairs, ordered, not_reversed = judged(kinds)
    right_vote, lenient_vote, _, ordered_vote, _ = judged(votes)
    return {"text": item["text"], "words": words, "actions": actions, "judges": kinds, "plan": segments,
            "split_right": split, "segment_bounds": None if bounds is None else np.asarray(bounds).tolist(),
            "readings": readings, "right": right, "right_lenient": lenient, "order_pairs": pairs,
            "order_right": ordered, "order_not_reversed": not_reversed,
            "right_vote": right_vote, "right_lenient_vote": lenient_vote, "order_right_vote": ordered_vote}


def _share(flags: list) -> float | None:
    told = [bool(f) for f in flags if f is not None]
    return sum(told) / len(told) if told else None


def _segment_figures(rows: list[dict], right: str = "right", lenient: str = "right_lenient") -> dict:
    """Judged segments right (``right``: the rows' key of their flags; ``lenient`` the lenient one),
    overall and per expected action, and the segments no judge reads."""
    per: dict = {}
    unjudged: dict = {}
    for r in rows:
        for w, a, ok, near in zip(r["words"], r["actions"], r[right], r[lenient]):
            if ok is None:
                key = a or f"'{w}' (no action)"
                unjudged[key] = unjudged.get(key, 0) + 1
                continue
            p = per.setdefault(a, {"n": 0, "right": 0, "lenient": 0})
            p["n"] += 1
            p["right"] += bool(ok)
            p["lenient"] += bool(near)
    judged = sum(p["n"] for p in per.values())
    return {"accuracy": sum(p["right"] for p in per.values()) / judged if judged else None,
            "accuracy_lenient": sum(p["lenient"] for p in per.values()) / judged if judged else None,
            "right": sum(p["right"] for p in per.values()),
            "right_lenient": sum(p["lenient"] for p in per.values()), "judged": judged,
            "unjudged": sum(unjudged.values()), "unjudged_by_action": dict(sorted(unjudged.items())),
            "per_action": {a: {**p, "accuracy": p["right"] / p["n"]} for a, p in sorted(per.items())}}


def tally(rows: list[dict]) -> dict:
    """The figures of judged prompts (``judge_prompt`` rows); ``segments_vote`` and ``order_vote``:
    every signed action read by the judge that reads it without its signature (a wave by the arms,
    the rest by the raw-feature vote)."""
    whole = [all(r["right"]) for r in rows if r["right"] and None not in r["right"]]

    def order(key: str) -> dict:
        return {"accuracy": _share([r[key] for r in rows]), "right": sum(bool(r[key]) for r in rows),
                "judged": sum(r[key] is not None for r in rows)}

    return {"segments": _segment_figures(rows),
            "segments_vote": _segment_figures(rows, "right_vote", "right_lenient_vote"),
            "all_right": {"accuracy": _share(whole), "right": sum(whole), "prompts": len(whole)},
            "order": order("order_right"), "order_not_reversed": order("order_not_reversed"),
            "order_vote": order("order_right_vote"),
            "split": {"accuracy": _share([r["split_right"] for r in rows]),
                      "right": sum(r["split_right"] for r in rows), "prompts": len(rows)}}


def reachable(rows: list[dict], judge, classifier, signed_table: dict | None = None) -> dict:
    """What copying real performances could score: each judged segment's expected action read by its
    judge on real training clips without their own takes (``part_judge_accuracy.leave_one_out``,
    ``ActionClassifier.reachable``; a signature on the real clips' segment-long windows,
    ``signed_table``: ``signature_accuracy.signature_table``), per action and the mean over the
    judged segments."""
    from .action_signatures import signed
    from .part_judge import CIRCLE, SAME_MOTION
    from .part_judge_accuracy import leave_one_out

    parts = leave_one_out(judge)
    actions = classifier.reachable() if classifier is not None else {}
    per = {}
    for r in rows:
        for a, k, ok in zip(r["actions"], r["judges"], r["right"]):
            if ok is None or a in per:
                continue
            if k == SIGNATURE:
                per[a] = float((signed_table or {}).get(signed(a), {}).get(signed(a), 0.0))
                continue
            cls = {LEGS: "walk" if a == CIRCLE else a, ARMS: SAME_MOTION.get(a, a)}.get(k, a)
            table = parts[k]["per_class"] if k in (LEGS, ARMS) else actions
            per[a] = (table.get(cls) or {}).get("accuracy", 0.0)
    told = [per[a] for r in rows for a, ok in zip(r["actions"], r["right"]) if ok is not None]
    return {"segments": float(np.mean(told)) if told else None, "per_action": dict(sorted(per.items()))}


def eval_sequences(model_dir=None, data=None, prompts=None, seed: int = 0, seconds: float | None = None,
                   candidates: int | None = None, max_prompts: int | None = None, generator=None, judge=None,
                   classifier=None, progress=None, show_progress: bool = True) -> dict:
    """Generate each held-out sequence as the product does and judge its segments (module
    docstring); prompt i on seed ``seed + i``. ``data``: the built dataset whose real training clips
    the judges read (default ``default_built_dir()``); ``judge`` / ``classifier``: a ``PartJudge`` /
    raw-feature ``ActionClassifier`` to use instead. Returns {"segments", "all_right", "order",
    "split", "targets", "settings", "rows", ...}."""
    from ..generation.generate import Request
    from ..generation.loaded_generator import loaded_generator
    from ..generation.sampling_params import or_defaults
    from ..models.motion_memory import take_of
    from ..motion.features import motion_features
    from ..plan.plan import read_plan
    from .action_classifier import ActionClassifier, built_dir
    from .part_judge import PartJudge

    items = load_sequences(prompts)
    if max_prompts is not None:
        if max_prompts < 1:
            raise ShapeMoveError(f"--max-prompts must be at least 1, got {max_prompts}")
        items = items[:max_prompts]
    candidates = or_defaults(candidates)[0]
    gen = generator if generator is not None else loaded_generator(model_dir)
    gen.set_retrieval(True)   # as `generate` makes it: retrieval on, captured takes compete
    gen.set_captured(True)
    if judge is None or classifier is None:
        data = built_dir(data, "eval sequences judges generated segments against real clips")
    if judge is None:
        judge = PartJudge.from_data(data, "train", progress=show_progress)
    if classifier is None:
        classifier = ActionClassifier.from_features(data, gen.known_actions, progress=show_progress)
    rows = []
    for i, it in enumerate(items):
        plan = read_plan(it["text"])
        m = gen.generate_batch([Request(it["text"], seconds=seconds, seed=seed + i, candidates=candidates)])[0]
        played = motion_features(m)   # what the rig plays
        bounds = m.segment_bounds if m.segment_bounds is not None else np.array([[0, m.num_frames]])
        row = judge_prompt(it, [s.text for s in plan.segments], played, bounds, judge, classifier,
                           sorted({take_of(c) for c in m.retrieved_clips}) or None)
        rows.append({**row, "seed": seed + i, "seconds": round(m.num_frames / m.fps, 2),
                     "made_as": list(m.segment_prompts) if m.segment_prompts else [m.prompt]})
        if progress is not None:
            progress((i + 1) / len(items), it["text"])
    from ..plan.segments import SEGMENT_SECONDS
    from .signature_accuracy import signature_table

    signed_table = signature_table(data, "train", SEGMENT_SECONDS) if data is not None else None
    return {**tally(rows), "reachable": reachable(rows, judge, classifier, signed_table), "targets": TARGETS,
            "judge": dict(judge.info),
            "classifier": dict(classifier.info) if classifier is not None else None,
            "settings": {"model": str(getattr(gen, "model_dir", model_dir)), "seed": seed, "seconds": seconds,
                         "candidates": candidates, "prompts": len(items),
                         "prompts_file": str(Path(prompts) if prompts else DEFAULT_PROMPTS)},
            "rows": rows}


def _pct(v) -> str:
    return "—" if v is None else f"{100 * v:.1f}%"


def format_results(res: dict) -> str:
    s, a, o, sp, tg, st = (res["segments"], res["all_right"], res["order"], res["split"], res["targets"],
                           res["settings"])
    lines = [f"Held-out one-prompt sequences ({Path(st['prompts_file']).name}, {st['prompts']} prompts): "
             f"segments right {s['right']} of {s['judged']} judged {_pct(s['accuracy'])} (target {_pct(tg['segments'])}; "
             f"{_pct(s['accuracy_lenient'])} with a specific form of the action counted), "
             f"order right {o['right']} of {o['judged']} {_pct(o['accuracy'])} (target {_pct(tg['order'])}; not "
             f"reversed {res['order_not_reversed']['right']} of {res['order_not_reversed']['judged']} "
             f"{_pct(res['order_not_reversed']['accuracy'])}), "
             f"split right {sp['right']} of {sp['prompts']} {_pct(sp['accuracy'])}, "
             f"prompts with every segment right {a['right']} of {a['prompts']} {_pct(a['accuracy'])}"]
    w = max([len(k) for k in s["per_action"]] + [6])
    reach = (res.get("reachable") or {}).get("per_action") or {}
    lines.append(f"  {'action'.ljust(w)}  {'n':>3}  {'right':>6}  {'lenient':>7}  {'real':>6}")
    for k, v in s["per_action"].items():
        lines.append(f"  {k.ljust(w)}  {v['n']:>3}  {_pct(v['accuracy']):>6}  {_pct(v['lenient'] / v['n']):>7}  "
                     f"{_pct(reach.get(k)):>6}")
    if res.get("reachable"):
        lines.append(f"real: the same judge on real training clips of the action, each without its own take; "
                     f"copying real performances could score {_pct(res['reachable']['segments'])} of these segments")
    if s["unjudged"]:
        lines.append(f"unjudged segments ({s['unjudged']}: no action of the vocabulary, or none the judges can name): "
                     + ", ".join(f"{k} {n}" for k, n in s["unjudged_by_action"].items()))
    v, ov = res.get("segments_vote"), res.get("order_vote")
    if v and ov:
        lines.append(f"without the signatures (jumps, squats, lying down, getting up, spins, kicks, jumping jacks by "
                     f"the vote, waves by the arms): segments right {v['right']} of {v['judged']} {_pct(v['accuracy'])}, order right "
                     f"{ov['right']} of {ov['judged']} {_pct(ov['accuracy'])}")
    lines.append("judges: an action with a physical signature by it (a flight, a dip, the head down, a rise, a turn, "
                 "a foot high ahead, a raised wrist swinging), gaits by the part judge's legs, gestures by its arms, "
                 "other actions by the "
                 "5-NN vote on pooled raw features (no TMA); order: the plan's segments in the expected order and, "
                 "for every two segments of judged actions, more of them shown in place than swapped (not "
                 "reversed: no fewer)")
    lines.append(f"one motion per prompt (seed {st['seed']} + i, "
                 + (f"{st['seconds']:g} s shared by the segments" if st["seconds"] else "the product's length")
                 + f", best of {st['candidates']} token samples per segment by the TMA)")
    return "\n".join(lines)


def add_arguments(p) -> None:
    """Options of `python -m shapemove eval sequences`."""
    from .report import add_output_arguments

    p.add_argument("--model", type=Path, default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--data", type=Path, default=None,
                   help="built dataset: its real training clips are the judges' references "
                        "(default $SHAPEMOVE_BUILT, else data/built)")
    p.add_argument("--prompts", type=Path, default=None,
                   help="held-out sequences (default configs/heldout_sequences.json)")
    p.add_argument("--seconds", type=float, default=None,
                   help="length of each motion, shared by its segments (default: the product's, 3 s a segment)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--candidates", type=int, default=None,
                   help="token samples per segment, the TMA keeps the closest (default: the product's; 1 = none)")
    p.add_argument("--max-prompts", type=int, default=None, metavar="N", help="only the first N prompts (a quick run)")
    add_output_arguments(p)


def from_cli(args) -> int:
    from .report import checked_seconds, run_and_show

    checked_seconds(args.seconds, 0.8)
    return run_and_show("eval sequences", args.quiet, lambda progress: eval_sequences(
        args.model, args.data, args.prompts, args.seed, args.seconds, args.candidates, args.max_prompts,
        progress=progress, show_progress=not args.quiet), format_results, args.json)
