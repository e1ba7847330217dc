"""``generate --prompts FILE --out DIR``: a motion file per line of a prompts file (docs/batches.md),
with a manifest, resume, ``--jobs``, ``--shard`` and ``--dask``; no Blender needed. The command's
other options are every line's defaults (a ``.jsonl`` line's own keys win) and its sampling
settings."""
from __future__ import annotations

from ..core.errors import ShapeMoveError


def run_generate_batch(args) -> int:
    from ..core.batch.generate_item import generate_item
    from ..core.batch.items import read_items
    from ..core.batch.shard import parse_shard
    from .batch_run import run_and_report, sampling_settings, where_of

    if args.prompt is not None:
        raise ShapeMoveError("give --prompt (one motion) or --prompts (a batch), not both")
    if args.out.suffix.lower() == ".npz":
        raise ShapeMoveError(f"with --prompts, --out is a folder (one .npz per prompt), got {args.out}")
    shard = parse_shard(args.shard)
    defaults = {"shape_text": args.shape_text, "betas": args.betas, "seconds": args.seconds, "seed": args.seed,
                "loop": args.loop, "in_place": args.in_place,
                "path": str(args.path.resolve()) if args.path is not None else None,
                "speed": args.speed, "stretch": args.stretch}
    settings = sampling_settings(args)          # refused before any model loads
    items, count = read_items(args.prompts, shard, defaults)
    where, named, model = where_of(args)
    return run_and_report("generate", generate_item, args, items, count, {**settings, **named}, where, model,
                          shard)
