"""A decoded real walk beside the original clip, from the side (issue #24's "look"): a PNG.

    python tools/decoded_walk_side.py --data data/built --clip dataset-1_walk_happy_001 \
        --checkpoint weights/default/savae.pt --out docs/codec_walk_side.png

Drawn with Pillow (no plotting library). Rows (same metres on the horizontal axis, the walk's own forward direction): the original clip
(its shape-aware motion, ``new_joint_vecs``) and the clip encoded and decoded on its own betas, the
Motion a user gets (``generation.decode.decode_tokens``: planted feet, IK); stick figures every
``--every`` frames, the root's path (black) and both ankles' paths (left blue, right red) with
their contact frames as dots. A last panel: forward position of the root and the ankles against
time, original solid, decoded dashed (the root's slope is its speed; flat ankle steps are plants).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

BONES = [(0, 1), (1, 4), (4, 7), (7, 10), (0, 2), (2, 5), (5, 8), (8, 11), (0, 3), (3, 6), (6, 9), (9, 12),
         (12, 15), (9, 13), (13, 16), (16, 18), (18, 20), (9, 14), (14, 17), (17, 19), (19, 21)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, required=True)
    ap.add_argument("--clip", required=True)
    ap.add_argument("--checkpoint", type=Path, default=Path("weights/default/savae.pt"))
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--every", type=int, default=6, help="a stick figure every N frames")
    ap.add_argument("--seconds", type=float, default=4.0, help="show the first N seconds")
    ap.add_argument("--no-search", action="store_true", help="the encoders' codes (default: searched for, as retargeting)")
    args = ap.parse_args(argv)

    import torch
    from PIL import Image, ImageDraw

    from shapemove.core.body.load import load_body_model
    from shapemove.core.eval.gait import mean_speed
    from shapemove.core.generation.decode import decode_tokens
    from shapemove.core.generation.retarget import encode_take, load_vae
    from shapemove.core.motion.contacts import detect_contacts
    from shapemove.core.motion.features import joints_from_features

    torch.set_num_threads(1)
    body = load_body_model(None)
    vae = load_vae(args.checkpoint, body)
    load = lambda sub: np.load(args.data / sub / f"{args.clip}.npy")  # noqa: E731
    betas = load("betas").reshape(-1)
    codes = encode_take(vae, load("norm_joint_vecs"), betas, load("new_joint_vecs"), not args.no_search)
    dec = decode_tokens(codes, vae, body, betas).joints.astype(np.float64)
    orig = joints_from_features(load("new_joint_vecs")[:len(dec)].astype(np.float64))
    n = min(len(dec), int(args.seconds * 20))
    # the side view: horizontal axis along the original root's overall direction of travel
    d = orig[n - 1, 0, [0, 2]] - orig[0, 0, [0, 2]]
    d /= max(np.linalg.norm(d), 1e-9)
    fwd = lambda j: j[..., 0] * d[0] + j[..., 2] * d[1]  # noqa: E731
    rows = [("original", orig[:n]), ("decoded (final Motion)", dec[:n])]
    xmin = min(fwd(j).min() for _, j in rows) - 0.3
    xmax = max(fwd(j).max() for _, j in rows) + 0.3
    W, ppm, pad = 1400, None, 40                      # width (px); pixels per metre from the travel
    ppm = (W - 2 * pad) / (xmax - xmin)
    row_h = int(2.0 * ppm) + 30                       # 2 m of height per figure row
    plot_h = 320
    img = Image.new("RGB", (W, 2 * row_h + plot_h + 60), "white")
    dr = ImageDraw.Draw(img)
    BLUE, RED, GREY, BLACK = (31, 119, 180), (214, 39, 40), (150, 150, 150), (0, 0, 0)
    left_leg, right_leg = {1, 4, 7, 10}, {2, 5, 8, 11}
    for r, (name, j) in enumerate(rows):
        top = 10 + r * row_h
        floor = top + row_h - 12
        px = lambda x: pad + (x - xmin) * ppm  # noqa: E731
        py = lambda y: floor - y * ppm  # noqa: E731
        x, y = fwd(j), j[..., 1]
        c = detect_contacts(j)
        dr.line([(pad, floor), (W - pad, floor)], fill=GREY)
        for t in range(0, n, args.every):
            for a, b in BONES:
                col = BLUE if b in left_leg else RED if b in right_leg else GREY
                dr.line([(px(x[t, a]), py(y[t, a])), (px(x[t, b]), py(y[t, b]))], fill=col, width=2)
        dr.line([(px(x[t, 0]), py(y[t, 0])) for t in range(n)], fill=BLACK, width=2)
        for k, (jt, col) in enumerate(((7, BLUE), (8, RED))):
            dr.line([(px(x[t, jt]), py(y[t, jt])) for t in range(n)], fill=col, width=1)
            for t in np.flatnonzero(c[:, k]):
                dr.ellipse([px(x[t, jt]) - 3, py(y[t, jt]) - 3, px(x[t, jt]) + 3, py(y[t, jt]) + 3], fill=col)
        dr.text((pad, top), f"{name}: {mean_speed(j):.2f} m/s, root travel {np.abs(np.diff(x[:, 0])).sum():.2f} m "
                f"in {n / 20:.1f} s (root black; ankles left blue / right red, dots = contact frames)", fill=BLACK)
    # forward position against time: original solid, decoded dashed
    top = 2 * row_h + 30
    lo = min(fwd(j)[:, [0, 7, 8]].min() for _, j in rows)
    hi = max(fwd(j)[:, [0, 7, 8]].max() for _, j in rows)
    tx = lambda t: pad + t / max(n - 1, 1) * (W - 2 * pad)  # noqa: E731
    fy = lambda v: top + plot_h - 10 - (v - lo) / max(hi - lo, 1e-9) * (plot_h - 30)  # noqa: E731
    dr.rectangle([pad, top, W - pad, top + plot_h], outline=GREY)
    for (name, j), dashed in zip(rows, (False, True)):
        for jt, col in ((0, BLACK), (7, BLUE), (8, RED)):
            v = fwd(j)[:, jt]
            for t in range(n - 1):
                if not dashed or t % 2 == 0:
                    dr.line([(tx(t), fy(v[t])), (tx(t + 1), fy(v[t + 1]))], fill=col, width=2)
    dr.text((pad + 5, top + 5), f"forward position (m, {lo:.1f} to {hi:.1f}) against time (0 to {n / 20:.1f} s): "
            "original solid, decoded dashed; root black, left ankle blue, right ankle red", fill=BLACK)
    dr.text((pad, img.height - 22), f"{args.clip}: original vs SA-VAE encode -> decode on its own betas "
            f"({args.checkpoint}); decoded / original speed {mean_speed(dec) / mean_speed(orig):.3f}x", fill=BLACK)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    img.save(args.out)
    print(f"wrote {args.out}: original {mean_speed(orig):.2f} m/s, decoded {mean_speed(dec):.2f} m/s "
          f"({mean_speed(dec) / mean_speed(orig):.3f}x)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
