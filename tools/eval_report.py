"""Write the evaluation tables into docs/evaluation.md from the JSON of `eval recon` / `generate` / `paraphrase` / `shape`.

    python tools/eval_report.py [--recon out/eval_recon.json] [--untrained out/eval_recon_untrained.json]
                                [--generate out/eval_generate.json] [--paraphrase out/eval_paraphrase.json]
                                [--paraphrase-blind out/eval_paraphrase_blind.json] [--shape out/eval_shape.json]
                                [--page docs/evaluation.md]

Each table sits between ``<!-- eval:recon -->`` / ``<!-- /eval:recon -->`` (and ``eval:generate``)
markers in the page and is replaced whole; the paper's figures stand beside for reference. The
paraphrase table (``eval:paraphrase``, with the blind set's column when its JSON exists) and the shape
table (``eval:shape``) are written only where the page has that block.
"""
from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

from shapemove.core.atomic import atomic_write_text

ROOT = Path(__file__).resolve().parents[1]

# (key, label, digits, paper's figure)
RECON_ROWS = [
    ("mpjpe_mm", "MPJPE, global (mm)", 1, "—"),
    ("mpjpe_local_mm", "MPJPE, root-aligned (mm)", 1, "—"),
    ("bone_err_mm", "bone-length error (mm)", 1, "45.9"),
    # the paper's figures stand only beside the paper's definitions (mean over ALL frames; GMD skate on
    # the foot joints); ours (over the frames past 5 mm; skate on the foot vertices) have no paper figure
    ("penetrate_all_cm", "penetrate, paper definition: mean over all frames (cm)", 3, "0.027"),
    ("float_all_cm", "float, paper definition: mean over all frames (cm)", 3, "0.266"),
    ("skate_joints_pct", "skate, GMD on the foot joints (%)", 2, "6.1"),
    ("penetrate_cm", "penetrate, over frames > 5 mm under (cm)", 2, "—"),
    ("float_cm", "float, over frames > 5 mm above (cm)", 2, "—"),
    ("skate_pct", "skate, foot mesh vertices (%)", 2, "—"),
    ("dyn_stable_pct", "dynamic stability (HUMOS: % frames with the ZMP in the base of support)", 1, "—"),
    ("code_usage_pct", "codebook usage (%)", 1, "—"),
]
GENERATE_ROWS = [
    ("r_precision_top1", "R-precision top 1", 3, "—"),
    ("r_precision_top3", "R-precision top 3", 3, "—"),
    ("matching_score", "matching score (lower is better)", 3, "—"),
    ("fid", "FID (TMA embeddings)", 3, "—"),
    ("penetrate_all_cm", "penetrate, paper definition: mean over all frames (cm)", 3, "0.027"),
    ("float_all_cm", "float, paper definition: mean over all frames (cm)", 3, "0.266"),
    ("skate_joints_pct", "skate, GMD on the foot joints (%)", 1, "6.1"),
    ("penetrate_cm", "penetrate, over frames > 5 mm under (cm)", 2, "—"),
    ("float_cm", "float, over frames > 5 mm above (cm)", 2, "—"),
    ("skate_pct", "skate, foot mesh vertices (%)", 1, "—"),
    ("dyn_stable_pct", "dynamic stability (HUMOS, %)", 1, "—"),
    ("height_err_cm", "height error of the predicted body (cm)", 2, "0.58"),
    ("waist_err_cm", "waist error of the predicted body (cm)", 2, "—"),
]


def _cell(col: dict | None, key: str, digits: int) -> str:
    v = None if col is None else col.get(key)
    return "—" if v is None else f"{float(v):.{digits}f}"


def recon_table(recon: dict, untrained: dict | None = None) -> str:
    head = ["metric", "trained SA-VAE"] + (["untrained (1 step)"] if untrained else []) + \
        ["ground truth (the data)", "paper (SA-VAE, for reference)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for key, label, digits, paper in RECON_ROWS:
        cells = [label, _cell(recon, key, digits)] + ([_cell(untrained, key, digits)] if untrained else []) + \
            [_cell(recon.get("ground_truth"), key, digits), paper]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def generate_table(gen: dict) -> str:
    head = ["metric", "generated", "real motions (ceiling)", "paper (ShapeMove, for reference)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for key, label, digits, paper in GENERATE_ROWS:
        lines.append("| " + " | ".join([label, _cell(gen, key, digits), _cell(gen.get("ground_truth"), key, digits),
                                        paper]) + " |")
    return "\n".join(lines)


PARAPHRASE_ROWS = [  # (label, result key, metric key): percentages of the held-out prompts
    ("generated motion (5 nearest training clips in TMA motion space), strict", "motion", "accuracy"),
    ("generated motion, lenient (an 'also' action counts)", "motion", "accuracy_lenient"),
    ("generated motion, merged (a pair the judge does not tell apart in real windows counts)", "motion",
     "accuracy_merged"),
    ("generated motion, judged without the TMA (5 nearest training clips in pooled raw features), strict",
     "motion_features", "accuracy"),
    ("... judged without the TMA, merged", "motion_features", "accuracy_merged"),
    ("reachable: a perfect generator under the TMA classifier (leave-one-source-out per action)", "reachable", "motion"),
    ("reachable under the raw-feature classifier", "reachable", "motion_features"),
    ("the same classifier on real test clips (ceiling), strict", "ceiling", "accuracy"),
    ("the same classifier on real test clips (ceiling), lenient (any of the clip's actions)", "ceiling", "accuracy_lenient"),
    ("prompt's TMA text vs action text prototypes, strict", "text", "accuracy"),
    ("prompt's TMA text vs action text prototypes, lenient", "text", "accuracy_lenient"),
    ("generated motion vs action text prototypes (older classifier), strict", "motion_vs_text_prototypes", "accuracy"),
    ("generated motion vs action text prototypes, lenient", "motion_vs_text_prototypes", "accuracy_lenient"),
]


def _paraphrase_cell(res: dict | None, key: str, metric: str) -> str:
    if res is None:
        return "—"
    col = ((res.get("classifier") or {}).get("ceiling") or {}) if key == "ceiling" else (res.get(key) or {})
    v = col.get(metric)
    return "—" if v is None else f"{100 * float(v):.1f} %"


def paraphrase_table(held: dict, blind: dict | None = None) -> str:
    """Right-action rates of `eval paraphrase` (held-out set, and the blind set when given); target 80 %."""
    def name(res, default):
        seeds = res.get("seeds") or [0]
        n = res["motion"]["prompts"] // len(seeds)
        return f"{default} ({n} prompts" + (f" x {len(seeds)} seeds)" if len(seeds) > 1 else ")")

    head = ["right action", name(held, "held-out paraphrases")] + ([name(blind, "blind held-out set")] if blind else [])
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for label, key, metric in PARAPHRASE_ROWS:
        cells = [label, _paraphrase_cell(held, key, metric)] + ([_paraphrase_cell(blind, key, metric)] if blind else [])
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def shape_table(res: dict) -> str:
    """`eval shape`: the head's height/waist errors per numeric form, and size words inside their ranges."""
    n = res["numeric"]
    lines = [f"| numeric shape text ({res['bodies']} new bodies) | texts | height error (cm) | waist error (cm) |",
             "|---|---|---|---|"]
    for form, d in n["per_form"].items():
        if d["texts"]:
            lines.append(f"| {form} | {d['texts']} | {d['height_err_cm']:.2f} | {d['waist_err_cm']:.2f} |")
    lines.append(f"| **all numeric** | {n['texts']} | **{n['height_err_cm']:.2f}** | **{n['waist_err_cm']:.2f}** |")
    words = res["adjectives"]["per_word"]
    lines += ["", "| size word | bodies in the word's ranges | mean height (cm) | mean waist / height |", "|---|---|---|---|"]
    for w, d in words.items():
        lines.append(f"| {w} | {100 * d['in_range']:.0f} % | {d['height_cm']:.1f} | {d['waist_to_height']:.3f} |")
    lines.append(f"| **all words** | **{100 * res['adjectives']['in_range']:.1f} %** | | |")
    return "\n".join(lines)


def replace_block(text: str, name: str, body: str) -> str:
    pattern = re.compile(rf"(<!-- eval:{name} -->\n).*?(\n<!-- /eval:{name} -->)", re.S)
    if not pattern.search(text):
        raise SystemExit(f"the page has no <!-- eval:{name} --> ... <!-- /eval:{name} --> block")
    return pattern.sub(lambda m: m.group(1) + body + m.group(2), text)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--recon", type=Path, default=ROOT / "out" / "eval_recon.json")
    ap.add_argument("--untrained", type=Path, default=ROOT / "out" / "eval_recon_untrained.json")
    ap.add_argument("--generate", type=Path, default=ROOT / "out" / "eval_generate.json")
    ap.add_argument("--paraphrase", type=Path, default=ROOT / "out" / "eval_paraphrase.json")
    ap.add_argument("--paraphrase-blind", type=Path, default=ROOT / "out" / "eval_paraphrase_blind.json")
    ap.add_argument("--shape", type=Path, default=ROOT / "out" / "eval_shape.json")
    ap.add_argument("--page", "--readme", dest="page", type=Path, default=ROOT / "docs" / "evaluation.md",
                    help="the Markdown page holding the marked tables (default docs/evaluation.md)")
    args = ap.parse_args(argv)
    text = args.page.read_text(encoding="utf-8")
    if args.recon.is_file():
        untrained = json.loads(args.untrained.read_text()) if args.untrained.is_file() else None
        text = replace_block(text, "recon", recon_table(json.loads(args.recon.read_text()), untrained))
    if args.generate.is_file():
        text = replace_block(text, "generate", generate_table(json.loads(args.generate.read_text())))
    if args.shape.is_file() and "<!-- eval:shape -->" in text:
        text = replace_block(text, "shape", shape_table(json.loads(args.shape.read_text())))
    if args.paraphrase.is_file():
        if "<!-- eval:paraphrase -->" in text:
            blind = json.loads(args.paraphrase_blind.read_text()) if args.paraphrase_blind.is_file() else None
            text = replace_block(text, "paraphrase", paraphrase_table(json.loads(args.paraphrase.read_text()), blind))
        else:
            print(f"{args.page} has no <!-- eval:paraphrase --> block: paraphrase table not written")
    atomic_write_text(args.page, text)
    print(f"updated the evaluation tables in {args.page}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
