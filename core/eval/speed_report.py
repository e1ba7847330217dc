"""`python -m shapemove eval speed`: the speed check's options, its table, its JSON (``speed.py``).

    eval speed --data DIR --checkpoint SAVAE.pt [--model MODEL_DIR] [--split test] [--feet]
               [--max-clips N] [--shape-clips 8] [--seeds 0 1] --json OUT

Prints, per action, the original clips' mean root speed, the decoded and final motions' speed
ratios (target >= 0.95) and velocity correlations; the short/tall shape check; with --model the
generated locomotion's ratios against the real clips.
"""
from __future__ import annotations

import math
from pathlib import Path

from ..atomic import atomic_write_json
from .speed import TARGET, speed_check


def add_arguments(p) -> None:
    p.add_argument("--data", type=Path, required=True, help="dataset folder from `data build`")
    p.add_argument("--split", default="test", choices=["train", "val", "test"])
    p.add_argument("--checkpoint", type=Path, required=True, help="SA-VAE run folder or .pt file")
    p.add_argument("--model", type=Path, default=None,
                   help="model folder (t5/, savae.pt): also measure generated locomotion against the real clips")
    p.add_argument("--json", type=Path, required=True, help="write the numbers here")
    p.add_argument("--feet", action="store_true",
                   help="also measure the root re-derived from the planted feet (motion/root_from_feet.py)")
    p.add_argument("--max-clips", type=int, default=None, help="at most N clips per action (seeded random subset)")
    p.add_argument("--shape-clips", type=int, default=8,
                   help="walk clips decoded on a short and a tall body (stride vs cadence); 0: skip")
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1], help="generation seeds per prompt (with --model)")
    p.add_argument("--no-search", action="store_true",
                   help="encode the real clips by the encoders alone (default: the codes searched for on each "
                        "clip's own body, as retargeting encodes a take)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def _f(v, fmt="{:.3f}") -> str:
    return "-" if v is None or (isinstance(v, float) and math.isnan(v)) else fmt.format(v)


def print_speed(result: dict) -> None:
    kinds = result["kinds"]
    print(f"root speed, {result['split']} split: decoded / original (target >= {TARGET:.2f}x), "
          "velocity correlation per frame")
    head = f"{'action':<8}{'clips':>6}{'orig m/s':>10}" + "".join(f"{k + ' x':>14}{'corr':>7}" for k in kinds)
    print(head + f"{'leg swing x':>13}")
    for name, s in [*result["actions"].items(), ("all", result["all"])]:
        print(f"{name:<8}{s['clips']:>6}{s['orig_mps']:>10.2f}"
              + "".join(f"{_f(s[k + '_ratio']):>14}{_f(s[k + '_corr'], '{:.2f}'):>7}" for k in kinds)
              + f"{_f(s['decoded_swing_ratio']):>13}")
    print("leg swing x: how far the decoded feet reach apart fore and aft / the clip's (< 1: the legs step short)")
    sh = result.get("shape")
    if sh:
        print(f"shape: {len(sh['clips'])} walks on a short and a tall body (leg {sh['leg_short_m']:.3f} -> "
              f"{sh['leg_tall_m']:.3f} m, ratio {sh['leg_ratio']:.3f})")
        for k in ("decoded", "final"):
            print(f"  {k:<8} stride ratio {sh[k + '_stride_ratio']:.3f}  cadence ratio {sh[k + '_cadence_ratio']:.3f} "
                  f"(within {1 - sh['cadence_tol']:.2f}-{1 + sh['cadence_tol']:.2f})  "
                  f"stride {sh[k + '_stride_short_m']:.2f} -> {sh[k + '_stride_tall_m']:.2f} m")
    gen = result.get("generated")
    if gen:
        print("generated locomotion / real clips of the action (same bodies):")
        for a, g in gen.items():
            print(f"  {a:<8} {g['samples']:>3} samples  real {g['real_mps']:.2f} m/s  decoded {g['decoded_ratio']:.3f}x  "
                  f"final {g['final_ratio']:.3f}x")


def from_cli(args) -> int:
    from tqdm import tqdm

    bar = tqdm(total=100, desc="eval speed", unit="%", disable=args.quiet)

    def progress(fraction, what):
        bar.update(max(0, round(100 * fraction) - bar.n))
        bar.set_postfix_str(str(what)[:40])

    try:
        result = speed_check(args.data, args.checkpoint, split=args.split, model_dir=args.model, feet=args.feet,
                             max_clips=args.max_clips, shape_clips=args.shape_clips, seeds=tuple(args.seeds),
                             progress=progress, search=not args.no_search)
    finally:
        bar.close()
    atomic_write_json(args.json, result, nan_to_null=True)
    print_speed(result)
    print(f"wrote {args.json}")
    return 0
