"""`python -m shapemove retarget --motion IN (--betas b0,…,b9 | --shape-text TEXT) [--checkpoint RUN]
--out OUT.npz [--naive]`: a captured motion (BVH, ASF/AMC, AMASS .npz) or a ShapeMove motion file
performed by another body.

The body: explicit betas, or a shape text - a measured sentence ("A person standing 190 cm tall,
with a waist circumference of 100 cm") or adjectives ("a tall, heavy-set man") - turned into
betas by matching the body's measurements (``core/body/shape_from_measurements.py``).
Default: through the SA-VAE (``core/generation/retarget.py``; the output keeps its motion tokens,
so it can be re-decoded for other bodies), unless its codes miss the take (decoded on the subject's
own body, more than ``take_fidelity.LOST_TAKE_MM`` off in the worst second: a fast kick the codec
flattens): then the take's own rotations with its feet planted, and a note says so
(``--no-fallback`` keeps the SA-VAE's motion anyway); ``--naive`` copies the rotations instead.
"""
from __future__ import annotations

from pathlib import Path

from ..core.errors import ShapeMoveError
from ..core.scene.motion_file import save_motion


def add_arguments(p):
    p.add_argument("--motion", type=Path, required=True, help="input motion: .bvh, .amc (with its .asf), AMASS .npz or a ShapeMove motion .npz")
    p.add_argument("--betas", default=None, help="target body shape b0,…,b9 (missing values are 0)")
    p.add_argument("--shape-text", default=None, help='target body as text, e.g. "A person standing 190 cm tall"')
    p.add_argument("--checkpoint", type=Path, default=None,
                   help="SA-VAE run folder or .pt (default: the embedded model's savae.pt)")
    p.add_argument("--out", type=Path, required=True, help="output motion file (.npz)")
    p.add_argument("--naive", action="store_true", help="copy the rotations instead of going through the SA-VAE")
    p.add_argument("--no-fallback", action="store_true",
                   help="keep the SA-VAE's motion even when its codes miss the take (default: the take's own "
                        "rotations, feet planted, when they do)")
    p.add_argument("--no-search", action="store_true",
                   help="the SA-VAE's encoders' codes, not searched for on the subject's body (faster, less faithful)")
    p.add_argument("--body-model", default=None, help="openbody (default) or an SMPL-family file")
    add_reader_arguments(p)


def add_reader_arguments(p):
    """Overrides of what a mocap file declares (shared with the commands that read mocap)."""
    p.add_argument("--source-fps", type=float, default=None,
                   help="read the file at this frame rate instead of its own (BVH Frame Time, AMC rate): for a "
                        "file whose header is wrong")
    p.add_argument("--angle-unit", choices=["deg", "rad"], default=None,
                   help="ASF/AMC: read rotation values in this unit whatever the files declare")


def reader_overrides(args) -> dict:
    return {k: v for k, v in (("source_fps", getattr(args, "source_fps", None)),
                              ("angle_unit", getattr(args, "angle_unit", None))) if v is not None}


def target_betas(body, betas_text: str | None, shape_text: str | None):
    """Exactly one of --betas / --shape-text -> (10,) betas."""
    from ..core.body.shape_from_measurements import betas_from_shape_text
    from ..core.generation.generate import parse_betas

    if (betas_text is None) == (shape_text is None):
        raise ShapeMoveError("give the target body with exactly one of --betas or --shape-text")
    return parse_betas(betas_text) if betas_text is not None else betas_from_shape_text(body, shape_text)


def run(args) -> int:
    from ..core.body.load import load_body_model
    from ..core.body.measure import format_body, measure
    from ..core.generation.retarget import load_vae, naive_retarget, retarget
    from ..core.generation.take_fidelity import LOST_TAKE_MM

    if args.out.suffix.lower() != ".npz":
        raise ShapeMoveError(f"--out must end in .npz, got {args.out}")
    if not args.motion.is_file():
        raise ShapeMoveError(f"motion file not found: {args.motion}")
    body = load_body_model(args.body_model)
    betas = target_betas(body, args.betas, args.shape_text)
    read = reader_overrides(args)
    if args.naive:
        motion = naive_retarget(args.motion, body, betas, read=read)
        how = "naive (rotations copied)"
    else:
        from tqdm import tqdm

        search = not getattr(args, "no_search", False)
        with tqdm(total=100, desc="searching codes", unit="%", disable=not search) as bar:
            motion = retarget(args.motion, load_vae(args.checkpoint, body), body, betas, read=read,
                              search=search, progress=lambda f: bar.update(round(100 * f) - bar.n),
                              fallback_mm=None if args.no_fallback else LOST_TAKE_MM)
        how = (f"SA-VAE, {len(motion.tokens)} tokens" if motion.tokens is not None
               else "the take's own rotations, feet planted: " + "; ".join(motion.notes))
    save_motion(args.out, motion)
    m = measure(body, motion.betas)
    print(f"wrote {args.out}: {motion.num_frames} frames ({motion.num_frames / motion.fps:.1f} s), {how}")
    print("betas: " + ",".join(f"{v:.2f}" for v in motion.betas))
    print("body: " + format_body(m))
    return 0
