"""`python -m shapemove render --prompts prompts.txt|prompts.jsonl --out DIR [--video]`.

Generates and renders each prompt headless: ``DIR/NNN_slug.blend``, ``DIR/NNN_slug.png`` (a strip
of frames), the motion ``DIR/NNN_slug.npz`` and with ``--video`` ``DIR/NNN_slug.mp4``, and
``DIR/manifest.jsonl`` with a line per prompt (docs/batches.md). A ``.txt`` has one prompt per
line; a ``.jsonl`` has objects with "prompt" and optional "shape_text", "seconds", "seed", "betas",
and the animation options (docs/animation.md) "loop", "in_place", "path" ([[x, z], ...] metres or
a JSON file next to the prompts file), "speed", "stretch", "root_motion" (PELVIS, OBJECT,
ROOT_BONE, NONE); an object with "sequence": [{"prompt", "seconds"}, ...] instead of "prompt" is
a timeline (one rig, one NLA strip per prompt). ``--loop``/``--in-place``/``--speed``/
``--stretch``/``--root-motion`` set defaults for every line. ``--library DIR`` adds your own
captioned motions to what the model retrieves (as ``generate --library``). A prompt that fails is
reported with its reason and skipped; the rest go on. Running the same command again skips the
prompts already rendered; ``--jobs N``, ``--shard I/N`` and ``--dask ADDRESS`` spread the batch
(``cli/batch_run.py``).
"""
from __future__ import annotations

from pathlib import Path

from ..core.errors import ShapeMoveError
from .batch_run import add_batch_arguments


def add_arguments(p):
    p.add_argument("--prompts", type=Path, required=True)
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--video", action="store_true", help="also render an MP4 of every frame (slower)")
    p.add_argument("--model", type=Path, default=None)
    p.add_argument("--library", type=Path, default=None,
                   help="a folder of your own captioned motions that compete with the model's samples (as "
                        "`generate --library`; one the model's codes cannot carry is played as captured)")
    p.add_argument("--frames", type=int, default=4, help="frames in each preview strip")
    p.add_argument("--resolution", type=int, nargs=2, default=(320, 320), metavar=("W", "H"))
    g = p.add_argument_group("animation defaults (a .jsonl line's own keys win)")
    g.add_argument("--loop", action="store_true", default=None, help="every prompt as a cycle")
    g.add_argument("--in-place", action="store_true", default=None, help="remove the root's horizontal travel")
    g.add_argument("--speed", type=float, default=None, help="0.5 to 2")
    g.add_argument("--stretch", type=float, default=None, metavar="SECONDS")
    g.add_argument("--root-motion", choices=["PELVIS", "OBJECT", "ROOT_BONE", "NONE"], default=None,
                   help="where the rig carries the travel (default PELVIS)")
    add_batch_arguments(p)


def run(args) -> int:
    from ..core.batch.items import LINE_KEYS, read_items
    from ..core.batch.shard import parse_shard
    from .batch_run import run_and_report, sampling_settings, where_of
    from .render_item import render_item

    shard = parse_shard(args.shard)
    if args.frames < 1 or min(args.resolution) < 16 or max(args.resolution) > 8192:
        raise ShapeMoveError("--frames must be >= 1 and --resolution 16 to 8192 pixels a side")
    defaults = {"loop": args.loop, "in_place": args.in_place, "speed": args.speed, "stretch": args.stretch,
                "root_motion": args.root_motion}
    items, count = read_items(args.prompts, shard, defaults, keys=(*LINE_KEYS, "root_motion"))
    if not args.dask:   # the workers of a cluster import bpy there; worker processes import it themselves
        import importlib.util

        if importlib.util.find_spec("bpy") is None:
            raise ShapeMoveError("the render command needs the bpy module: pip install bpy==5.0.1")
    where, named, model = where_of(args)
    settings = {**sampling_settings(args), **named, "frames": args.frames,
                "resolution": [int(v) for v in args.resolution], "video": bool(args.video)}
    return run_and_report("render", render_item, args, items, count, settings, where, model, shard)
