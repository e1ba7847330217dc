"""Generated motions drawn from the front and from the side, left limbs blue, right limbs red:
a quick look at what prompts produce, independent of Blender (Pillow stick figures).

    python tools/prompt_views.py --model weights/default --out out/views.png \
        --prompt "a boxer throws a jab" --prompt "someone raises the left hand" [--motion seq.npz]

Each prompt is one row: ``--frames`` poses evenly spaced in time, seen from the front (the camera
looks at the body's face at frame 0: the body's LEFT side appears on the image's RIGHT, as for a
person facing you) and then from the body's right side (forward is to the image's right). Joints
are the final Motion's (after IK and foot planting, ``scene.motion_file.fk_joints``); the floor
(y = 0) is the grey line. The row's title is the prompt and the body source.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

LEFT = {1, 4, 7, 10, 13, 16, 18, 20}
RIGHT = {2, 5, 8, 11, 14, 17, 19, 21}
BONES = [(0, 1), (1, 4), (4, 7), (7, 10), (0, 2), (2, 5), (5, 8), (8, 11), (0, 3), (3, 6), (6, 9), (9, 12),
         (12, 15), (9, 13), (13, 16), (16, 18), (18, 20), (9, 14), (14, 17), (17, 19), (19, 21)]


def body_frame(joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(forward, left) unit XZ axes of the body at frame 0 (hips and shoulders across)."""
    across = (joints[0, 1] - joints[0, 2]) + (joints[0, 16] - joints[0, 17])   # right -> left
    left = np.array([across[0], 0.0, across[2]])
    left /= max(np.linalg.norm(left), 1e-9)
    forward = np.cross(left, [0.0, 1.0, 0.0])                                   # left x up = forward
    return forward / max(np.linalg.norm(forward), 1e-9), left


def draw_row(draw, joints, x0, y0, cell, frames, title, font=None):
    from PIL import ImageDraw  # noqa: F401

    fwd, left = body_frame(joints)
    root0 = joints[0, 0]
    picks = np.linspace(0, len(joints) - 1, frames).round().astype(int)
    scale = cell * 0.42
    draw.text((x0 + 4, y0 + 2), title, fill=(0, 0, 0), font=font)
    for view in range(2):
        for k, t in enumerate(picks):
            cx = x0 + (view * frames + k) * cell + cell // 2
            base = y0 + cell - 12
            draw.line([(cx - cell // 2 + 6, base), (cx + cell // 2 - 6, base)], fill=(170, 170, 170))
            p = joints[t] - root0
            h = p @ left if view == 0 else p @ fwd           # front: body's left to image right
            if view == 1:
                h = h - (joints[t, 0] - root0) @ fwd          # side: centred on the pelvis, travel shown below
            v = joints[t, :, 1]
            pts = [(cx + float(h[j]) * scale, base - float(v[j]) * scale) for j in range(22)]
            for a, b in BONES:
                col = (30, 90, 220) if b in LEFT else (220, 40, 40) if b in RIGHT else (20, 20, 20)
                draw.line([pts[a], pts[b]], fill=col, width=2)
            label = f"{t / 20:.1f}s" + ("" if view == 0 else f" +{float((joints[t, 0] - root0) @ fwd):.1f}m")
            draw.text((cx - cell // 2 + 6, base + 1), label, fill=(90, 90, 90), font=font)
        draw.text((x0 + view * frames * cell + 4, y0 + 14), "front" if view == 0 else "side (forward ->)",
                  fill=(90, 90, 90), font=font)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", type=Path, default=None)
    ap.add_argument("--prompt", action="append", default=[])
    ap.add_argument("--motion", action="append", type=Path, default=[],
                    help="a saved motion file (a loop, a timeline) drawn as a row of its own")
    ap.add_argument("--shape-text", default=None)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--cell", type=int, default=150)
    ap.add_argument("--seconds", type=float, default=4.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--no-retrieval", action="store_true")
    args = ap.parse_args(argv)

    from PIL import Image, ImageDraw

    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.scene.motion_file import fk_joints, load_motion

    if not args.prompt and not args.motion:
        ap.error("give at least one --prompt or --motion")

    gen = Generator(args.model)
    gen.set_retrieval(not args.no_retrieval)
    rows = []
    for i, prompt in enumerate(args.prompt):
        m = gen.generate_batch([Request(prompt, args.shape_text, None, args.seconds, args.seed + i)])[0]
        rows.append((prompt + f"   [{m.shape_source or 'head'}]", np.asarray(fk_joints(gen.body, m))[:, :22]))
    for path in args.motion:
        m = load_motion(path)
        rows.append((f"{path.name}: {m.prompt}", np.asarray(fk_joints(gen.body, m))[:, :22]))
    W, H = 2 * args.frames * args.cell, len(rows) * (args.cell + 10)
    img = Image.new("RGB", (W, H), (255, 255, 255))
    d = ImageDraw.Draw(img)
    for r, (title, j) in enumerate(rows):
        draw_row(d, j, 0, r * (args.cell + 10), args.cell, args.frames, title)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    img.save(args.out)
    print(f"wrote {args.out} ({len(rows)} prompts)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
