"""Left and right, and two things at once: held-out prompts judged by body part.

    res = eval_parts("weights/default", data="data/built")
    res["sides"]["named_side_moves_most"], res["two_things"]["both"], res["two_things"]["legs"], res["two_things"]["arms"]

Two held-out prompt sets, written by hand and never used for training or tuning (no prompt is a
training caption: ``tests/test_heldout_parts.py``):

- ``configs/heldout_sides.json``: {"text", "side": "left"|"right", "part": "hand"|"foot", "action"}:
  raise or wave a named hand, kick or lift a named foot. Right when the named side's hand (or foot)
  moves most relative to the pelvis, in the body's own frame (``part_judge.side_of``).
- ``configs/heldout_two_things.json``: {"text", "legs", "arms"}: a locomotion and a gesture at once,
  only the pairs of ``compose_parts.HELD_OUT_PAIRS`` (never composed for training). Legs right when
  the judged gait is the expected one ("walk in a circle": the path circles while the legs move),
  arms right when the judged gesture is; both right when both are.

Their tuning sets, ``configs/tuning_two_things.json`` and ``configs/tuning_sides.json``, say
``"tuning": true``; given a tuning two-things file and no sides file, the tuning sides are judged
beside it (``TUNING_SIDES``), so a tuning run shows no held-out prompt.

One generated motion per prompt (seed ``seed + i`` for the i-th prompt of each set; the product's
best-of-N TMA choice among token samples unless ``candidates`` says otherwise), its features
computed from what the rig plays (``motion_features`` of the planted Motion), judged by
``part_judge.PartJudge`` built from the real training clips of the built dataset ``data``;
``judge_real`` is the judge's own accuracy on the real test clips (``part_judge_accuracy``), the
most a generator can be credited with. ``reachable`` is what copying real performances could
score: per class, how often the judge reads a real clip of it right when that clip's take is not
among its references (``part_judge_accuracy.leave_one_out``), as a kept memory clip is judged; for
the two-things set, the mean over its prompts (both: the mean of legs x arms). A class with one
captured take (``march``, ``beckon``) reads 0 there. ``retrieval=False`` runs a model that reads retrieved clips
(``ShapeMoveT5.memory``, ``memory_k`` > 0) with an empty memory: the prompt alone.
Targets (issue #23): sides >= 90 %, both >= 70 %, legs and arms >= 85 % each. The bar (issue #52):
``two_things["barred"]``, over the prompts whose legs and arms classes each have at least
``BAR_TAKES`` captured takes among the judge's references (single-take classes, ``march`` and
``beckon``, are reported, not barred), both, legs and arms each at least ``BAR_SHARE`` x what
copying real performances is credited with on those prompts (``reachable_parts``).
"""
from __future__ import annotations

from pathlib import Path

from ..errors import ShapeMoveError

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
DEFAULT_SIDES = CONFIGS / "heldout_sides.json"
DEFAULT_TWO_THINGS = CONFIGS / "heldout_two_things.json"
TUNING_SIDES = CONFIGS / "tuning_sides.json"   # the sides judged beside a tuning two-things set, unless named
MAX_PROMPTS_BYTES = 1 << 20
TARGETS = {"sides": 0.90, "both": 0.70, "legs": 0.85, "arms": 0.85}
BAR_TAKES = 3      # a class with fewer captured takes is reported, not barred
BAR_SHARE = 0.9    # the bar: this share of what real performances are credited with
SIDES, PARTS = ("left", "right"), ("hand", "foot")


def _prompts(doc, path: Path) -> list:
    items = doc.get("prompts") if isinstance(doc, dict) else doc
    if not isinstance(items, list) or not items:
        raise ShapeMoveError(f"{path}: no prompts (expected {{\"prompts\": [...]}})")
    return items


def load_sides(path=None) -> list[dict]:
    """The left/right prompts [{text, side, part, action, tuning}] of a JSON file (``tuning``: the
    file says ``"tuning": true``, a set to tune on: ``configs/tuning_sides.json``)."""
    from ..io.limits import read_json

    path = Path(path) if path else DEFAULT_SIDES
    doc = read_json(path, "left/right prompt list", MAX_PROMPTS_BYTES)
    tuning = isinstance(doc, dict) and doc.get("tuning") is True
    out = []
    for i, it in enumerate(_prompts(doc, path)):
        if not (isinstance(it, dict) and isinstance(it.get("text"), str) and it.get("side") in SIDES
                and it.get("part") in PARTS):
            raise ShapeMoveError(f"{path}: prompt {i} must be {{\"text\": ..., \"side\": \"left\"|\"right\", "
                                 f"\"part\": \"hand\"|\"foot\"}}")
        out.append({"text": it["text"], "side": it["side"], "part": it["part"], "action": str(it.get("action", "")),
                    "tuning": tuning})
    return out


def load_two_things(path=None) -> list[dict]:
    """The two-things prompts [{text, legs, arms}] of a JSON file; every (legs, arms) pair must be
    one of ``HELD_OUT_PAIRS`` (pairs composed for training would not test anything new), unless the
    file says ``"tuning": true`` (a set to tune on, of trained pairs: ``configs/tuning_two_things.json``)."""
    from ..data.compose_parts import HELD_OUT_PAIRS
    from ..io.limits import read_json

    path = Path(path) if path else DEFAULT_TWO_THINGS
    doc = read_json(path, "two-things prompt list", MAX_PROMPTS_BYTES)
    tuning = isinstance(doc, dict) and doc.get("tuning") is True
    out = []
    for i, it in enumerate(_prompts(doc, path)):
        if not (isinstance(it, dict) and isinstance(it.get("text"), str) and isinstance(it.get("legs"), str)
                and isinstance(it.get("arms"), str)):
            raise ShapeMoveError(f"{path}: prompt {i} must be {{\"text\": ..., \"legs\": ..., \"arms\": ...}}")
        if not tuning and (it["legs"], it["arms"]) not in HELD_OUT_PAIRS:
            raise ShapeMoveError(f"{path}: prompt {i} pairs {it['legs']!r} with {it['arms']!r}, not one of the "
                                 "held-out pairs of core/data/compose_parts.py (HELD_OUT_PAIRS)")
        out.append({"text": it["text"], "legs": it["legs"], "arms": it["arms"], "tuning": tuning})
    return out


def sides_beside(sides, two_items: list[dict]):
    """The left/right prompt file judged beside ``two_items``: ``sides`` when named, else the
    tuning sides beside a tuning two-things set (``TUNING_SIDES``), else None (the held-out ones)."""
    if sides is None and two_items and two_items[0]["tuning"]:
        return TUNING_SIDES
    return sides


def _share(flags: list[bool]) -> float | None:
    return sum(flags) / len(flags) if flags else None


def _by(rows: list[dict], key: str, flags: tuple[str, ...]) -> dict:
    out: dict = {}
    for r in rows:
        out.setdefault(str(r[key]), []).append(r)
    return {k: {"n": len(v), **{f: _share([x[f] for x in v]) for f in flags}} for k, v in sorted(out.items())}


def eval_parts(model_dir=None, data=None, sides=None, two_things=None, seed: int = 0, seconds: float = 4.0,
               candidates: int | None = None, retrieval: bool = True, generator=None, judge=None,
               judge_check: bool = True, progress=None, show_progress: bool = True, by_parts: bool = True,
               retrieved: int | None = None, retrieval_first: float | None = None) -> dict:
    """Generate one motion per held-out prompt and judge it by part (module docstring). Returns
    {"sides": {...}, "two_things": {...}, "judge_real", "targets", "settings", "rows": {...}}."""
    from ..generation.generate import Generator, Request
    from ..generation.sampling_params import or_defaults
    from ..models.motion_memory import take_of
    from ..motion.features import motion_features
    from .action_classifier import built_dir
    from .part_judge import PartJudge, arms_right, legs_right
    from .part_judge_accuracy import leave_one_out, real_accuracy

    two_items = load_two_things(two_things)
    sides = sides_beside(sides, two_items)
    side_items = load_sides(sides)
    candidates, retrieved, retrieval_first, _ = or_defaults(candidates, retrieved, retrieval_first)
    if judge is None:
        data = built_dir(data, "eval parts judges generated motions against real clips")
        judge = PartJudge.from_data(data, "train", progress=show_progress)
    real = real_accuracy(judge, data, "test", progress=show_progress) if judge_check and data is not None else None
    gen = generator if generator is not None else Generator(model_dir)
    reads_memory = bool(getattr(gen, "reads_memory", False))
    if reads_memory:
        gen.set_retrieval(retrieval)
    total, done = len(side_items) + len(two_items), 0

    def generate(text: str, s: int):
        nonlocal done
        m = gen.generate_batch([Request(text, seconds=seconds, seed=s, candidates=candidates, by_parts=by_parts,
                                        retrieved=retrieved if retrieval else 0, retrieval_first=retrieval_first)])[0]
        done += 1
        if progress is not None:
            progress(done / total, text)
        how = {"part_prompts": list(m.part_prompts) if m.part_prompts else None,
               "mirrored": bool(m.mirrored or m.arms_mirrored), "retrieved_clips": list(m.retrieved_clips)}
        played = motion_features(m)   # what the rig plays (a plain prompt's decoded features differ)
        return judge.judge([played], [{take_of(c) for c in m.retrieved_clips}])[0], bool(m.warnings), how

    side_rows, two_rows = [], []
    for i, it in enumerate(side_items):
        j, warned, how = generate(it["text"], seed + i)
        side_rows.append({**it, "judged": j, "right": j[f"{it['part']}_side"] == it["side"], "warned": warned, **how})
    for i, it in enumerate(two_items):
        j, warned, how = generate(it["text"], seed + i)
        lr, ar = legs_right(it["legs"], j), arms_right(it["arms"], j)
        two_rows.append({**it, "pair": f"{it['legs']} + {it['arms']}", "judged": j, "legs_right": lr,
                         "arms_right": ar, "both_right": lr and ar, "warned": warned, **how})
    reach = reachable_parts(leave_one_out(judge), two_items)
    return {
        "sides": {"named_side_moves_most": _share([r["right"] for r in side_rows]), "prompts": len(side_rows),
                  "tuning_set": bool(side_items and side_items[0]["tuning"]),
                  "per_part": _by(side_rows, "part", ("right",)), "per_side": _by(side_rows, "side", ("right",))},
        "two_things": {"both": _share([r["both_right"] for r in two_rows]),
                       "legs": _share([r["legs_right"] for r in two_rows]),
                       "arms": _share([r["arms_right"] for r in two_rows]), "prompts": len(two_rows),
                       "tuning_set": bool(two_items and two_items[0]["tuning"]),
                       "per_pair": _by(two_rows, "pair", ("both_right", "legs_right", "arms_right")),
                       "barred": barred_parts(two_rows, reach)},
        "targets": TARGETS,
        "judge_real": real,
        "reachable": reach,
        "judge": dict(judge.info),
        "settings": {"model": str(getattr(gen, "model_dir", model_dir)), "seed": seed, "seconds": seconds,
                     "candidates": candidates, "samples_per_prompt": 1, "by_parts": by_parts,
                     "retrieved": retrieved if retrieval else 0, "retrieval_first": retrieval_first,
                     "retrieval": ("on" if retrieval else "off") if reads_memory else "none (the model reads no memory)",
                     "sides_file": str(Path(sides) if sides else DEFAULT_SIDES),
                     "two_things_file": str(Path(two_things) if two_things else DEFAULT_TWO_THINGS)},
        "rows": {"sides": side_rows, "two_things": two_rows},
    }


def reachable_parts(reach: dict, two_items: list[dict]) -> dict:
    """``leave_one_out`` of the judge, and for the two-things prompts the mean over them of the
    expected legs and arms classes' reach (the judge's own classes: ``walk in a circle`` is a walk,
    ``legs_label``; ``wave goodbye`` is judged as a wave) and of their product (both)."""
    from .part_judge import SAME_MOTION, legs_label

    legs = [reach["legs"]["per_class"].get(legs_label([it["legs"]]), {}).get("accuracy", 0.0) for it in two_items]
    arms = [reach["arms"]["per_class"].get(SAME_MOTION.get(it["arms"], it["arms"]), {}).get("accuracy", 0.0)
            for it in two_items]
    mean = lambda v: sum(v) / len(v) if v else None  # noqa: E731
    return {**reach, "two_things": {"legs": mean(legs), "arms": mean(arms),
                                    "both": mean([a * b for a, b in zip(legs, arms)])}}


def barred_parts(rows: list[dict], reach: dict) -> dict:
    """Both, legs and arms right over the two-things ``rows`` whose expected legs and arms classes
    each have at least ``BAR_TAKES`` takes among the judge's references (``leave_one_out``'s
    counts), beside what real performances are credited with on the same rows
    (``reachable_parts``) and the bar, ``BAR_SHARE`` x that."""
    from .part_judge import SAME_MOTION, legs_label

    def takes(part: str, cls: str | None) -> int:
        return int((reach[part]["per_class"].get(cls) or {}).get("takes", 0))

    kept = [r for r in rows if takes("legs", legs_label([r["legs"]])) >= BAR_TAKES
            and takes("arms", SAME_MOTION.get(r["arms"], r["arms"])) >= BAR_TAKES]
    real = reachable_parts(reach, kept)["two_things"] if kept else {"legs": None, "arms": None, "both": None}
    got = {k: _share([r[f"{k}_right"] for r in kept]) for k in ("both", "legs", "arms")}
    bar = {k: None if real[k] is None else BAR_SHARE * real[k] for k in got}
    return {**got, "prompts": len(kept), "left_out": sorted({r["pair"] for r in rows} - {r["pair"] for r in kept}),
            "reachable": {k: real[k] for k in got}, "bar": bar,
            "met": all(got[k] is not None and bar[k] is not None and got[k] >= bar[k] for k in got) if kept else None}


def _pct(v) -> str:
    return "—" if v is None else f"{100 * v:.1f}%"


def format_results(res: dict) -> str:
    s, t, tg = res["sides"], res["two_things"], res["targets"]
    lines = [f"{'Tuning-set' if s.get('tuning_set') else 'Held-out'} left/right prompts ({s['prompts']}): the named side moves most {_pct(s['named_side_moves_most'])} "
             f"(target {_pct(tg['sides'])}); " + ", ".join(f"{k} {_pct(v['right'])} of {v['n']}" for k, v in s["per_part"].items()),
             f"{'Tuning-set' if t.get('tuning_set') else 'Held-out'} two-things prompts ({t['prompts']}): both parts right {_pct(t['both'])} (target {_pct(tg['both'])}), "
             f"legs {_pct(t['legs'])}, arms {_pct(t['arms'])} (target {_pct(tg['legs'])} each)"]
    w = max([len(p) for p in t["per_pair"]] + [4])
    lines.append(f"  {'pair'.ljust(w)}  {'n':>2}  {'both':>6}  {'legs':>6}  {'arms':>6}")
    for p, v in t["per_pair"].items():
        lines.append(f"  {p.ljust(w)}  {v['n']:>2}  {_pct(v['both_right']):>6}  {_pct(v['legs_right']):>6}  {_pct(v['arms_right']):>6}")
    real = res.get("judge_real")
    if real:
        lines.append(f"the judge on real {real['split']} clips: legs {_pct(real['legs']['accuracy'])} of {real['legs']['n']}, "
                     f"arms {_pct(real['arms']['accuracy'])} of {real['arms']['n']}, side {_pct(real['side']['accuracy'])} "
                     f"of {real['side']['n']} (clips and their mirrors), circle path {_pct(real['path']['accuracy'])} "
                     f"of {real['path']['n']}")
    reach = res.get("reachable")
    if reach:
        rt = reach["two_things"]
        few = [f"{c} {_pct(v['accuracy'])} ({v['takes']} take{'s' * (v['takes'] != 1)})" for part in ("legs", "arms")
               for c, v in reach[part]["per_class"].items() if v["accuracy"] < 0.9]
        lines.append(f"copying real performances (each judged without its own take) could score: legs {_pct(rt['legs'])}, "
                     f"arms {_pct(rt['arms'])}, both {_pct(rt['both'])} on these two-things prompts; classes read "
                     f"right under 90 % of the time this way: {', '.join(few) or 'none'}")
    b = t.get("barred")
    if b and b["prompts"]:
        lines.append(f"the bar (pairs of classes with >= {BAR_TAKES} takes, {b['prompts']} prompts; left out: "
                     f"{', '.join(b['left_out']) or 'none'}): both {_pct(b['both'])}, legs {_pct(b['legs'])}, arms "
                     f"{_pct(b['arms'])} against {BAR_SHARE:g}x real: {_pct(b['bar']['both'])}, {_pct(b['bar']['legs'])}, "
                     f"{_pct(b['bar']['arms'])} ({'met' if b['met'] else 'not met'})")
    st = res["settings"]
    lines.append(f"one motion per prompt (seed {st['seed']} + i, {st['seconds']} s, best of {st['candidates']} token "
                 f"samples by the TMA), retrieval {st['retrieval']}")
    rows = res["rows"]["sides"] + res["rows"]["two_things"]
    lines.append(f"by body part: {'on' if st.get('by_parts', True) else 'off'}; composed {sum(bool(r.get('part_prompts')) for r in rows)}, "
                 f"mirrored {sum(bool(r.get('mirrored')) for r in rows)}, a retrieved clip kept for "
                 f"{sum(bool(r.get('retrieved_clips')) for r in rows)} of {len(rows)} prompts "
                 f"({st.get('retrieved', 0)} clips offered per prompt; judged without their own takes)")
    return "\n".join(lines)


def add_arguments(p) -> None:
    """Options of `python -m shapemove eval parts`."""
    from .report import add_output_arguments

    p.add_argument("--model", type=Path, default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--data", type=Path, default=None,
                   help="built dataset: its real training clips are the judge's references, its test clips check the "
                        "judge (default $SHAPEMOVE_BUILT, else data/built)")
    p.add_argument("--sides", type=Path, default=None,
                   help="left/right prompts (default configs/heldout_sides.json; configs/tuning_sides.json beside a "
                        "tuning two-things file)")
    p.add_argument("--two-things", type=Path, default=None,
                   help="two-things prompts (default configs/heldout_two_things.json)")
    p.add_argument("--seconds", type=float, default=4.0, help="length of each generated motion")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--candidates", type=int, default=None,
                   help="token samples per prompt, the TMA keeps the closest (default: the product's, 8; 1 = none)")
    p.add_argument("--no-retrieval", action="store_true",
                   help="a model that reads retrieved clips gets none (an empty memory): the prompt alone")
    p.add_argument("--no-parts", action="store_true",
                   help="generate each prompt whole: no composition by body part, no mirroring to the named side")
    p.add_argument("--retrieved", type=int, default=None, metavar="CLIPS",
                   help="real clips nearest by caption added to the candidates (default: the product's; 0: none)")
    p.add_argument("--retrieval-first", type=float, default=None, metavar="SIM",
                   help="caption similarity from which only retrieved clips compete (default: the product's)")
    p.add_argument("--no-judge-check", action="store_true", help="skip the judge's accuracy on the real test clips")
    add_output_arguments(p)


def from_cli(args) -> int:
    from .report import checked_seconds, run_and_show

    checked_seconds(args.seconds, 0.5)
    return run_and_show("eval parts", args.quiet, lambda progress: eval_parts(
        args.model, args.data, args.sides, args.two_things, args.seed, args.seconds, args.candidates,
        retrieval=not args.no_retrieval, judge_check=not args.no_judge_check, progress=progress,
        show_progress=not args.quiet, by_parts=not args.no_parts, retrieved=args.retrieved,
        retrieval_first=args.retrieval_first), format_results, args.json)
