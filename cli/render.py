"""`python -m shapemove render --prompts prompts.txt|prompts.jsonl --out DIR [--video]`.

Generates and renders each prompt headless: ``DIR/NNN_slug.blend``, ``DIR/NNN_slug.png`` (a strip
of frames) and with ``--video`` ``DIR/NNN_slug.mp4``. A ``.txt`` has one prompt per line; a
``.jsonl`` has objects with "prompt" and optional "shape_text", "seconds", "seed", "betas", and the
animation options (docs/animation.md) "loop", "in_place", "path" ([[x, z], ...] metres or a JSON
file next to the prompts file), "speed", "stretch", "root_motion" (PELVIS, OBJECT, ROOT_BONE, NONE);
an object with "sequence": [{"prompt", "seconds"}, ...] instead of "prompt" is a timeline (one
rig, one NLA strip per prompt). ``--loop``/``--in-place``/``--speed``/``--stretch``/``--root-motion``
set defaults for every line. ``--library DIR`` adds your own captioned motions to what the model
retrieves (as ``generate --library``). A prompt that fails is reported with its reason and skipped;
the rest go on.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

from ..core.errors import ShapeMoveError
from ..core.scene.motion_file import save_motion


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


def read_prompts(path: Path) -> list[dict]:
    if not path.is_file():
        raise ShapeMoveError(f"prompts file not found: {path}")
    lines = [ln for ln in path.read_text(encoding="utf-8", errors="replace").splitlines() if ln.strip()]
    if path.suffix.lower() == ".jsonl":
        items = []
        for i, ln in enumerate(lines, 1):
            try:
                obj = json.loads(ln)
            except json.JSONDecodeError as exc:
                raise ShapeMoveError(f"{path}:{i}: not valid JSON ({exc.msg})") from None
            if not isinstance(obj, dict) or ("prompt" not in obj and not isinstance(obj.get("sequence"), list)):
                raise ShapeMoveError(f"{path}:{i}: each line needs an object with a \"prompt\" "
                                     "(or a \"sequence\" of {\"prompt\", \"seconds\"})")
            items.append(obj)
    else:
        items = [{"prompt": ln.strip()} for ln in lines if not ln.lstrip().startswith("#")]
    if not items:
        raise ShapeMoveError(f"{path} holds no prompts")
    return items


ANIMATION_KEYS = ("loop", "in_place", "path", "speed", "stretch")


def item_animation(it: dict, args, base: Path):
    """The ``Animation`` of one batch item: its own keys, else the command line's defaults; a
    "path" given as a file name is read next to the prompts file."""
    from ..core.generation.animate import animation_from

    params = {k: it.get(k, getattr(args, k, None)) for k in ANIMATION_KEYS}
    if isinstance(params["path"], str):
        params["path"] = str(base / params["path"])
    return animation_from(params)


def _generate_item(gen, it: dict, i: int, args, base: Path):
    from ..core.generation.animate import animate
    from ..core.generation.generate import Request, parse_betas
    from ..core.generation.in_place import in_place
    from ..core.generation.sequence import generate_sequence

    betas = parse_betas(it["betas"]) if it.get("betas") is not None else None
    seed = int(it.get("seed", i))
    if isinstance(it.get("sequence"), list):
        segs = it["sequence"]
        if not all(isinstance(s, dict) and "prompt" in s and "seconds" in s for s in segs):
            raise ShapeMoveError("a \"sequence\" is a list of {\"prompt\", \"seconds\"} objects")
        motion = generate_sequence(gen, [(s["prompt"], s["seconds"]) for s in segs], it.get("shape_text"), betas, seed)
        return in_place(motion) if it.get("in_place", args.in_place) else motion
    return animate(gen, Request(it.get("prompt"), it.get("shape_text"), betas, it.get("seconds"), seed),
                   item_animation(it, args, base))


def slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")[:40] or "prompt"


def run(args) -> int:
    from tqdm import tqdm

    from ..core.generation.generate import Generator

    items = read_prompts(args.prompts)
    try:
        import bpy  # noqa: F401

        from ..shapemove_addon.headless import build_scene_file, render_video
    except ImportError:
        raise ShapeMoveError("the render command needs the bpy module: pip install bpy==5.0.1") from None
    for i, it in enumerate(items):   # bad options are refused before any model loads
        try:
            item_animation(it, args, args.prompts.parent)
        except ShapeMoveError as exc:
            raise ShapeMoveError(f"{args.prompts} item {i + 1}: {exc}") from None
    gen = Generator(args.model)
    if args.library is not None:
        print(f"retrieval memory: {gen.add_library(args.library)} motions added from {args.library}")
    failed = []
    for i, it in enumerate(tqdm(items, desc="render", unit="prompt")):
        label = it.get("prompt") or " then ".join(str(s.get("prompt", "")) for s in it.get("sequence") or [])
        stem = args.out / f"{i:03d}_{slug(str(label))}"
        try:
            motion = _generate_item(gen, it, i, args, args.prompts.parent)
            for note in motion.notes:   # a library clip played as captured
                tqdm.write(f"prompt {i}: {note}")
            save_motion(stem.with_suffix(".npz"), motion)
            build_scene_file(motion, gen.body, stem.with_suffix(".blend"), stem.with_suffix(".png"),
                             frames=args.frames, resolution=tuple(args.resolution),
                             root_motion=str(it.get("root_motion") or args.root_motion or "PELVIS").upper())
            if args.video:
                render_video(stem.with_suffix(".blend"), stem.with_suffix(".mp4"))
        except ShapeMoveError as exc:
            failed.append((label, str(exc)))
            tqdm.write(f"skipped prompt {i} ({str(label)[:40]!r}): {exc}")
    print(f"rendered {len(items) - len(failed)} of {len(items)} prompts into {args.out}")
    for p, why in failed:
        print(f"  failed: {p!r}: {why}")
    return 0 if len(failed) < len(items) else 1
