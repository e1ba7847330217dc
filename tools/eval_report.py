"""Write the evaluation tables into the README from the JSON of `eval recon` / `eval generate`.

    python tools/eval_report.py [--recon out/eval_recon.json] [--untrained out/eval_recon_untrained.json]
                                [--generate out/eval_generate.json] [--readme README.md]

Each table sits between ``<!-- eval:recon -->`` / ``<!-- /eval:recon -->`` (and ``eval:generate``)
markers in the README and is replaced whole; the paper's figures stand beside for reference.
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


def replace_block(text: str, name: str, body: str) -> str:
    pattern = re.compile(rf"(<!-- eval:{name} -->\n).*?(\n<!-- /eval:{name} -->)", re.S)
    if not pattern.search(text):
        raise SystemExit(f"README has no <!-- eval:{name} --> ... <!-- /eval:{name} --> block")
    return pattern.sub(lambda m: m.group(1) + body + m.group(2), text)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--recon", type=Path, default=ROOT / "out" / "eval_recon.json")
    ap.add_argument("--untrained", type=Path, default=ROOT / "out" / "eval_recon_untrained.json")
    ap.add_argument("--generate", type=Path, default=ROOT / "out" / "eval_generate.json")
    ap.add_argument("--readme", type=Path, default=ROOT / "README.md")
    args = ap.parse_args(argv)
    text = args.readme.read_text(encoding="utf-8")
    if args.recon.is_file():
        untrained = json.loads(args.untrained.read_text()) if args.untrained.is_file() else None
        text = replace_block(text, "recon", recon_table(json.loads(args.recon.read_text()), untrained))
    if args.generate.is_file():
        text = replace_block(text, "generate", generate_table(json.loads(args.generate.read_text())))
    atomic_write_text(args.readme, text)
    print(f"updated the evaluation tables in {args.readme}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
