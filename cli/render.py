"""`python -m shapemove render --prompts prompts.txt|prompts.jsonl --out DIR [--video]`.

Generates and renders each prompt headless: ``DIR/NNN_slug.blend``, ``DIR/NNN_slug.png`` (a strip
of frames) and with ``--video`` ``DIR/NNN_slug.mp4``. A ``.txt`` has one prompt per line; a
``.jsonl`` has objects with "prompt" and optional "shape_text", "seconds", "seed", "betas".
A prompt that fails is reported with its reason and skipped; the rest go on.
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
    p.add_argument("--frames", type=int, default=4, help="frames in each preview strip")
    p.add_argument("--resolution", type=int, nargs=2, default=(320, 320), metavar=("W", "H"))


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
            if not isinstance(obj, dict) or "prompt" not in obj:
                raise ShapeMoveError(f"{path}:{i}: each line needs an object with a \"prompt\"")
            items.append(obj)
    else:
        items = [{"prompt": ln.strip()} for ln in lines if not ln.lstrip().startswith("#")]
    if not items:
        raise ShapeMoveError(f"{path} holds no prompts")
    return items


def slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")[:40] or "prompt"


def run(args) -> int:
    from tqdm import tqdm

    from ..core.generation.generate import Generator, parse_betas

    items = read_prompts(args.prompts)
    try:
        import bpy  # noqa: F401

        from ..shapemove_addon.headless import build_scene_file, render_video
    except ImportError:
        raise ShapeMoveError("the render command needs the bpy module: pip install bpy==5.0.1") from None
    gen = Generator(args.model)
    failed = []
    for i, it in enumerate(tqdm(items, desc="render", unit="prompt")):
        stem = args.out / f"{i:03d}_{slug(str(it.get('prompt', '')))}"
        try:
            betas = parse_betas(it["betas"]) if it.get("betas") is not None else None
            motion = gen.generate(it.get("prompt"), it.get("shape_text"), betas, it.get("seconds"), int(it.get("seed", i)))
            save_motion(stem.with_suffix(".npz"), motion)
            build_scene_file(motion, gen.body, stem.with_suffix(".blend"), stem.with_suffix(".png"),
                             frames=args.frames, resolution=tuple(args.resolution))
            if args.video:
                render_video(stem.with_suffix(".blend"), stem.with_suffix(".mp4"))
        except ShapeMoveError as exc:
            failed.append((it.get("prompt"), str(exc)))
            tqdm.write(f"skipped prompt {i} ({str(it.get('prompt'))[:40]!r}): {exc}")
    print(f"rendered {len(items) - len(failed)} of {len(items)} prompts into {args.out}")
    for p, why in failed:
        print(f"  failed: {p!r}: {why}")
    return 0 if len(failed) < len(items) else 1
