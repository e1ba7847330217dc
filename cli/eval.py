"""`python -m shapemove eval KIND ...`: evaluation commands, each printing a table beside the
ground truth and writing the numbers as JSON (atomically).

    eval recon --data DIR [--split test] --checkpoint RUN|savae.pt --json OUT [--max-clips N] [--base-only] [--no-search]

``recon``: SA-VAE reconstruction (``core/eval/recon.py``). JSON: the reconstruction's metrics as
flat keys (mpjpe_mm, bone_err_mm, penetrate_cm, float_cm, skate_pct, dyn_stable_pct,
code_usage_pct, clips) plus "ground_truth": {the same keys} (NaN -> null).

``generate``: text-to-motion metrics (``core/eval/generate_eval.py``, ``from_cli(args)``; the
kind is listed only when that module exists; its own ``add_arguments(parser)`` replaces the
arguments defined here if it has one).

Adding a kind: write ``add_KIND(subparsers)`` (setting ``_run``) and list it in ``KINDS``.
"""
from __future__ import annotations

import importlib
from pathlib import Path

from ..core.atomic import atomic_write_json


# -- eval recon ------------------------------------------------------------------------------------
def add_recon(sub):
    p = sub.add_parser("recon", help="SA-VAE reconstruction metrics on a dataset split",
                       description="SA-VAE reconstruction metrics on a dataset split, beside the ground truth")
    p.add_argument("--data", type=Path, required=True, help="dataset folder from `data build`")
    p.add_argument("--split", default="test", choices=["train", "val", "test"])
    p.add_argument("--checkpoint", type=Path, required=True, help="SA-VAE run folder or .pt file")
    p.add_argument("--json", type=Path, required=True, help="write the metrics here")
    p.add_argument("--max-clips", type=int, default=None, help="evaluate a seeded random subset of N clips")
    p.add_argument("--body-model", default=None, help="openbody (default) or an SMPL-family file")
    p.add_argument("--base-only", action="store_true",
                   help="a codec with a residual code: decode the base codes alone (what the T5 writes)")
    p.add_argument("--no-search", action="store_true",
                   help="decode the encoders' codes instead of searching for the codes closest to each clip "
                        "(as retargeting encodes a take)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(_run=run_recon)


def run_recon(args) -> int:
    from tqdm import tqdm

    from ..core.errors import ShapeMoveError
    from ..core.eval.recon import eval_recon
    from ..core.eval.report import print_table

    if args.max_clips is not None and args.max_clips < 1:
        raise ShapeMoveError("--max-clips must be at least 1")
    bar = tqdm(total=100, desc="eval recon", unit="%", disable=args.quiet)

    def progress(fraction, clip_id):
        bar.update(round(100 * fraction) - bar.n)
        bar.set_postfix_str(clip_id)

    clips: list = []
    try:
        result = eval_recon(args.data, args.checkpoint, split=args.split, body=args.body_model,
                            max_clips=args.max_clips, progress=progress, per_clip=clips, base_only=args.base_only,
                            search=not args.no_search)
    finally:
        bar.close()
    atomic_write_json(args.json, result, nan_to_null=True)
    print_table({**result, "frames": sum(c["frames"] for c in clips)}, result["ground_truth"],
                title=f"SA-VAE reconstruction, {args.split} split", name="reconstruction")
    print(f"codebook usage: {result['code_usage_pct']:.1f}%   wrote {args.json}")
    return 0


# -- eval generate (core/eval/generate_eval.py, when present) ---------------------------------------
def _generate_module():
    try:
        return importlib.import_module("...core.eval.generate_eval", __name__)
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.endswith("generate_eval"):
            return None
        raise


def add_generate(sub):
    mod = _generate_module()
    if mod is None:
        return
    p = sub.add_parser("generate", help="text-to-motion metrics (generated motions beside the real clips)",
                       description="text-to-motion metrics (generated motions beside the real clips)")
    mod.add_arguments(p)
    p.set_defaults(_run=lambda args: _exit_code(mod.from_cli(args)))


def _exit_code(result) -> int:
    """An int result is the exit code; anything else (e.g. the metrics dict) means success."""
    return result if isinstance(result, int) and not isinstance(result, bool) else 0


# -- eval retarget (HUMOS's application: SA-VAE retargeting against naive) ----------------------------
RETARGET_BODIES = {"a very tall, heavy-set man": "height 195 cm, waist 110 cm", "a short, slim woman": "height 152 cm, waist 64 cm"}


def add_retarget(sub):
    p = sub.add_parser("retarget", help="SA-VAE retargeting against naive retargeting onto new bodies",
                       description="Random test clips moved onto two bodies (a very tall heavy-set man, a short "
                                   "slim woman) by the SA-VAE (encode -> decode with new betas) and naively "
                                   "(copy rotations, scale the root path); physics on the new body's mesh")
    p.add_argument("--data", type=Path, required=True, help="dataset folder from `data build`")
    p.add_argument("--split", default="test", choices=["train", "val", "test"])
    p.add_argument("--checkpoint", type=Path, required=True, help="SA-VAE run folder or .pt file")
    p.add_argument("--json", type=Path, required=True, help="write the metrics here")
    p.add_argument("--max-clips", type=int, default=10, help="a seeded random subset of N clips (default 10)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--no-search", action="store_true",
                   help="the SA-VAE side: the encoders' codes instead of the codes searched for on the subject's body")
    p.set_defaults(_run=run_retarget)


def run_retarget(args) -> int:
    import numpy as np

    from ..core.body.load import load_body_model
    from ..core.body.shape_from_measurements import betas_from_shape_text
    from ..core.errors import ShapeMoveError
    from ..core.eval.retarget_compare import KEYS, compare_retargeting
    from ..core.train.motion_dataset import read_split

    clips = read_split(args.data, args.split)
    if not clips:
        raise ShapeMoveError(f"{args.data}: the {args.split} split is empty")
    if args.max_clips < 1:
        raise ShapeMoveError("--max-clips must be at least 1")
    rng = np.random.default_rng(args.seed)
    clips = [clips[i] for i in sorted(rng.choice(len(clips), min(args.max_clips, len(clips)), replace=False))]
    body = load_body_model(None)
    bodies = [betas_from_shape_text(body, text) for text in RETARGET_BODIES.values()]
    result = compare_retargeting(args.data, args.checkpoint, clips, bodies, body=body, search=not args.no_search)
    result["bodies"] = list(RETARGET_BODIES)
    atomic_write_json(args.json, result, nan_to_null=True)
    src = result.get("source")  # the capture on its own fitted body, for reference
    cols = [("SA-VAE", "savae"), ("auto", "auto"), ("naive", "naive"), ("naive/fr", "naive_frame"), ("swap", "swap")] + (
        [("source", "source")] if src else [])
    print(f"{'metric':<20}" + "".join(f"{label:>10}" for label, _ in cols))
    for k in KEYS:
        print(f"{k:<20}" + "".join(f"{result[name][k]:>10.2f}" for _, name in cols))
    print("naive/fr: naive with each frame's lowest point on the floor (no hovering); auto: the product's Retarget "
          f"(the take's own rotations, feet planted, for the {result['auto']['fallbacks']} clips the codes miss)")
    print(f"{len(clips)} clips x {len(bodies)} bodies; wrote {args.json}")
    return 0


# the evaluations whose module defines add_arguments(p) and from_cli(args): (command, module, help)
MODULE_KINDS = [
    ('shape', 'shape_eval',
     "the [BETA] head on numeric shape texts and size words of new bodies"),
    ('shape-words', 'shape_words_eval',
     "bodies the text describes: gender, age, muscle, height and weight (issue #25), on the parser + fit path or the [BETA] head"),
    ('paraphrase', 'paraphrase_eval',
     "held-out paraphrases: generated motion's action (5 nearest training clips in TMA motion space), per action"),
    ('parts', 'parts_eval',
     "held-out left/right and two-things prompts, judged by body part (legs, arms, side)"),
    ('sequences', 'sequence_eval',
     "held-out one-prompt sequences ('X, then Y'): each segment judged by body part or raw features, their order, the plan's split"),
    ('speed', 'speed_report',
     "root speed of decoded and generated walks/jogs/runs against the real clips"),
    ('codec-actions', 'codec_actions',
     "captured clips of each action judged as captured and as decoded by an SA-VAE"),
]


def _module_kind(command: str, module: str, help_text: str):
    def add(sub):
        mod = importlib.import_module(f"...core.eval.{module}", __name__)
        p = sub.add_parser(command, help=help_text, description=mod.__doc__.splitlines()[0])
        mod.add_arguments(p)
        p.set_defaults(_run=mod.from_cli)
    return add


KINDS = [add_recon, add_generate, add_retarget, *(_module_kind(*k) for k in MODULE_KINDS)]


def add_arguments(p):
    sub = p.add_subparsers(dest="kind", metavar="KIND", required=True)
    for add in KINDS:
        add(sub)


def run(args) -> int:
    return _exit_code(args._run(args))
