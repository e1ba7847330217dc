"""`python -m shapemove sequence --prompt "walks forward" --seconds 4 --prompt "sits down" --seconds 2
... --out seq.npz`: a timeline of prompts as one motion for one body, each segment continuing from
the previous one's last tokens (docs/animation.md). ``--regenerate K --motion seq.npz --seed N``
samples segment K (1-based) again and keeps the others."""
from __future__ import annotations

from pathlib import Path

from ..core.atomic import ensure_parent
from ..core.errors import ShapeMoveError
from ..core.scene.motion_file import load_motion, save_motion


def add_arguments(p):
    p.add_argument("--prompt", action="append", default=[], help="a segment's motion text (repeat, in order)")
    p.add_argument("--seconds", action="append", type=float, default=[],
                   help="that segment's length (one per --prompt; none: each the length its words ask, else 3 s)")
    p.add_argument("--shape-text", default=None, help="body text for the whole timeline")
    p.add_argument("--betas", default=None, help="explicit body shape b0,...,b9")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--temperature", type=float, default=1.0)
    p.add_argument("--top-k", type=int, default=50)
    p.add_argument("--candidates", type=int, default=None, help="token samples per segment (default 8)")
    p.add_argument("--guidance", type=float, default=None)
    p.add_argument("--regenerate", type=int, default=None, metavar="K",
                   help="re-generate segment K (1-based) of --motion with --seed; the other segments are kept")
    p.add_argument("--motion", type=Path, default=None, help="the timeline to change with --regenerate")
    p.add_argument("--no-parts", action="store_true",
                   help="generate segments of two things at once whole, not by body part")
    p.add_argument("--no-library", action="store_true",
                   help="no captured take competes: a timeline of the model's codes (docs/animation.md)")
    p.add_argument("--in-place", action="store_true", help="remove the root's horizontal travel")
    p.add_argument("--model", type=Path, default=None)
    p.add_argument("--body-model", default=None)
    p.add_argument("--out", type=Path, required=True)


def run(args) -> int:
    from ..core.generation.sampling_params import DEFAULT_CANDIDATES, check_candidates, check_guidance, check_sampling
    from ..core.generation.sequence import check_segments

    if args.out.suffix.lower() != ".npz":
        raise ShapeMoveError(f"--out must end in .npz, got {args.out}")
    check_sampling(args.seed, args.temperature, args.top_k)
    candidates = check_candidates(DEFAULT_CANDIDATES if args.candidates is None else args.candidates)
    guidance = check_guidance(args.guidance)
    overridden = []   # (prompt, the seconds its words ask, the --seconds that won)
    if args.regenerate is not None:
        if args.motion is None:
            raise ShapeMoveError("--regenerate needs --motion (the timeline to change)")
        base = load_motion(args.motion)
        if base.segment_bounds is None:
            raise ShapeMoveError(f"{args.motion} is not a timeline of prompts (no segments)")
        if not 1 <= args.regenerate <= len(base.segment_bounds):
            raise ShapeMoveError(f"--regenerate must be 1..{len(base.segment_bounds)} for {args.motion}")
        if len(args.prompt) > 1 or len(args.seconds) > 1:
            raise ShapeMoveError("with --regenerate give at most one --prompt and one --seconds (the segment's new ones)")
    else:
        if args.seconds and len(args.prompt) != len(args.seconds):
            raise ShapeMoveError(f"give one --seconds per --prompt, or none ({len(args.prompt)} prompts, "
                                 f"{len(args.seconds)} lengths)")
        from ..core.generation.course_shapes import model_course_seconds
        from ..core.plan.plan import own_seconds
        from ..core.plan.words import read_words

        readings = [read_words(str(p)) for p in args.prompt]
        once_round = model_course_seconds(args.model)   # "walks in a circle": the time to go once round
        lengths = args.seconds or [own_seconds(w, once_round) for w in readings]   # "for ten seconds", else 3 s
        segments = check_segments(list(zip(args.prompt, lengths)))
        overridden = [(p, w.seconds, sec) for p, w, sec in zip(args.prompt, readings, args.seconds)
                      if w.seconds not in (None, sec)]
    ensure_parent(args.out)
    from ..core.generation.generate import parse_betas
    from ..core.generation.loaded_generator import loaded_generator
    from ..core.generation.in_place import in_place
    from ..core.generation.sequence import generate_sequence, regenerate_segment, segment_codes
    from ..core.generation.stitched_timeline import segment_sources

    betas = parse_betas(args.betas) if args.betas else None
    gen = loaded_generator(args.model, args.body_model)
    gen.set_captured(not args.no_library)
    if args.regenerate is not None:
        motion = regenerate_segment(gen, base, args.regenerate - 1, args.seed, args.prompt[0] if args.prompt else None,
                                    args.seconds[0] if args.seconds else None, args.temperature, args.top_k,
                                    candidates, guidance, by_parts=not args.no_parts)
    else:
        from tqdm import tqdm

        with tqdm(total=len(segments) + 1, desc="sequence", unit="segment") as bar:
            def progress(fraction, message):
                bar.n = round(fraction * bar.total)
                bar.set_postfix_str(message[:40])
                bar.refresh()

            motion = generate_sequence(gen, segments, args.shape_text, betas, args.seed, args.temperature, args.top_k,
                                       candidates, guidance, progress=progress, by_parts=not args.no_parts)
    if args.in_place:
        motion = in_place(motion)
    save_motion(args.out, motion)
    import sys

    for w in motion.warnings:
        print(f"warning: {w}", file=sys.stderr)
    for p, said, sec in overridden:
        print(f"note: --seconds {sec:g} won over the {said:g} s {p!r} asks (leave out --seconds for its words' lengths)")
    print(f"wrote {args.out}: {motion.num_frames} frames ({motion.num_frames / motion.fps:.1f} s), "
          f"{len(motion.segment_bounds)} segments, IK error {motion.ik_error_cm:.2f} cm")
    n = len(motion.segment_bounds)
    own_arms = segment_codes(motion, arms=True) if motion.num_tokens else [None] * n
    sources = segment_sources(motion) or [""] * n   # a timeline of finished segments: each one's source
    for (s, e), p, a, src in zip(motion.segment_bounds, motion.segment_prompts, own_arms, sources):
        print(f"  frames {int(s):4d}-{int(e) - 1:4d}  {p}{'  (by body part)' if a is not None else ''}"
              f"{f'  [{src}]' if src else ''}")
    return 0
