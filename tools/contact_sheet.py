"""The README's picture: a few prompts on different bodies, generated with a model folder (the embedded
default model unless --model) and rendered headless the same way as `python -m shapemove render`
(``shapemove_addon.headless.build_scene_file``: Workbench preview strip), one row per prompt with its
texts and the body's measured height above it (two lines, large enough to read when the README
shows the picture at about half size).

    python tools/contact_sheet.py [--model weights/default] [--out docs/contact_sheet.png]
                                  [--frames 3] [--size 200] [--seed 0]

Needs bpy and Pillow (both installed by `make setup`). Takes about a minute on a CPU.
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# (prompt, shape text): different actions on different bodies, all in words the product is sold on
SHEET = [
    ("a person jogs forward and waves", "a tall, heavy-set man"),
    ("someone stretches both arms above the head", "a short, slim woman"),
    ("somebody crouches down and stands back up", "a stocky man"),
    ("a person walks forward", "a very tall, lanky person"),
]
FONT_SIZE = 20
LABEL_H = 2 * FONT_SIZE + 16  # two lines of text
BACKGROUND = (255, 255, 255)


def render_rows(model, frames: int, size: int, seed: int, tmp: Path) -> list[tuple[Path, str]]:
    """One preview strip per SHEET row: (png, two-line label)."""
    from shapemove.core.body.measure import measure
    from shapemove.core.generation.generate import Generator
    from shapemove.shapemove_addon.headless import build_scene_file

    gen = Generator(model)
    rows = []
    for i, (prompt, shape) in enumerate(SHEET):
        motion = gen.generate(prompt, shape, seed=seed)
        png = tmp / f"{i}.png"
        build_scene_file(motion, gen.body, tmp / f"{i}.blend", png, frames=frames, resolution=(size, size))
        height = measure(gen.body, motion.betas)["height_cm"]
        label = f'"{prompt}"\n"{shape}": {height:.0f} cm, {motion.num_frames / motion.fps:.1f} s'
        rows.append((png, label))
        print(f"{i + 1}/{len(SHEET)} " + label.replace("\n", "  /  "))
    return rows


def compose(rows: list[tuple[Path, str]], out: Path) -> Path:
    """Strips stacked top to bottom, each under a white band holding its label."""
    from PIL import Image, ImageDraw, ImageFont

    strips = [Image.open(p).convert("RGB") for p, _ in rows]
    width = max(s.width for s in strips)
    sheet = Image.new("RGB", (width, sum(s.height + LABEL_H for s in strips)), BACKGROUND)
    draw = ImageDraw.Draw(sheet)
    try:
        font = ImageFont.load_default(size=FONT_SIZE)
    except TypeError:  # Pillow < 10.1: one fixed size
        font = ImageFont.load_default()
    y = 0
    for strip, (_, label) in zip(strips, rows):
        draw.multiline_text((8, y + 5), label, fill=(20, 20, 20), font=font, spacing=4)
        sheet.paste(strip, (0, y + LABEL_H))
        y += strip.height + LABEL_H
    out.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(out, optimize=True)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", type=Path, default=ROOT / "weights" / "default")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "contact_sheet.png")
    ap.add_argument("--frames", type=int, default=3, help="frames per prompt")
    ap.add_argument("--size", type=int, default=200, help="pixels per frame (square)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        rows = render_rows(args.model, args.frames, args.size, args.seed, Path(tmp))
        compose(rows, args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
