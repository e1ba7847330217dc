"""`python -m shapemove generate --prompt TEXT | --prompts FILE [--shape-text TEXT] [--betas b0,…,b9] [--seconds S]
[--seed N] [--temperature T] [--loop] [--in-place] [--path PATH.json] [--speed X | --stretch S]
--out OUT.npz`: text -> body shape + motion file (animation options: docs/animation.md). A prompt of
motions in order ("walks forward, then sits down") is made as a timeline of them (``core/plan/``);
``--explain`` prints the plan as JSON and generates nothing; ``--plan PLAN.json`` generates from that
JSON, edited."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.atomic import ensure_parent
from ..core.errors import ShapeMoveError
from ..core.generation.sampling_params import check_sampling
from ..core.scene.motion_file import save_motion


def add_arguments(p):
    p.add_argument("--prompt", default=None, help='motion text, e.g. "a person jogs forward and waves"')
    p.add_argument("--prompts", type=Path, default=None,
                   help="a batch: a .txt file of prompts or a .jsonl of objects with per-line options; --out is "
                        "then a folder with a motion per line and manifest.jsonl (docs/batches.md)")
    p.add_argument("--shape-text", default=None, help='body text, e.g. "a tall, heavy-set man" or a measured sentence')
    p.add_argument("--betas", default=None, help="explicit body shape b0,…,b9 (overrides the predicted one)")
    p.add_argument("--shape-from", choices=["auto", "head"], default="auto",
                   help="auto: a shape text with measurements or size words is fitted on the mesh, other text goes "
                        "through the T5's [BETA] head; head: always the [BETA] head")
    p.add_argument("--seconds", type=float, default=None, help="motion length (default: the model decides, <= 10 s)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--temperature", type=float, default=1.0, help="sampling temperature; 0 = greedy")
    p.add_argument("--top-k", type=int, default=50)
    p.add_argument("--candidates", type=int, default=None,
                   help="token samples drawn; the text-motion model keeps the one closest to the prompt (default 8; 1 = none)")
    p.add_argument("--guidance", type=float, default=None,
                   help="classifier-free guidance scale (default: the model's, 2 for models trained with null prompts; 0 = none)")
    p.add_argument("--model", type=Path, default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--body-model", default=None, help="openbody (default) or a path to SMPL-family model files")
    p.add_argument("--out", type=Path, default=None, help="the motion file to write (.npz)")
    p.add_argument("--explain", action="store_true",
                   help="print the plan of the prompt as JSON (its segments in order, each with its share of the "
                        "length and what the words were understood to ask) and generate nothing; with --out PLAN.json "
                        "the plan is written there, to edit and generate from with --plan")
    p.add_argument("--plan", type=Path, default=None, metavar="PLAN.json",
                   help="generate from a plan: the JSON --explain prints, edited (actions, side, course, distance, "
                        "count, seconds per segment...: docs/prompts.md); takes the place of --prompt")
    p.add_argument("--library", type=Path, default=None,
                   help="a folder of your own captioned motions added to the retrieval memory (no retraining)")
    p.add_argument("--no-library", action="store_true",
                   help="no captured take competes: the built-in motion library's takes and your --library clips are "
                        "not played as captured; every motion is generated from the model's codes")
    p.add_argument("--no-retrieval", action="store_true",
                   help="the model's motion memory is not used: no retrieved clips among the candidates, no captured "
                        "clips of a part's action; the T5 writes everything from the prompt alone")
    p.add_argument("--retrieval-prefix", type=int, default=None, metavar="CODES",
                   help="half the candidates continue the first CODES codes (4 frames each) of the nearest "
                        "clips by caption (default 2; 0 = none)")
    p.add_argument("--retrieved", type=int, default=None, metavar="CLIPS",
                   help="real clips of the model's memory nearest by caption compete with the samples "
                        "(default 2; 0 = none)")
    p.add_argument("--retrieval-first", type=float, default=None, metavar="SIM",
                   help="from this caption similarity (0-1) only the retrieved clips compete (default: never)")
    p.add_argument("--no-parts", action="store_true",
                   help="generate the prompt whole: no legs + arms composition of two things at once, no mirroring "
                        "to a named left or right, no circle walked for 'in a circle', no turn given back for 'turns around'")
    add_animation_arguments(p)
    from .batch_run import add_batch_arguments

    add_batch_arguments(p)


def add_animation_arguments(p):
    """The animation options (docs/animation.md), shared with ``render``'s defaults."""
    g = p.add_argument_group("animation")
    g.add_argument("--loop", action="store_true",
                   help="a cycle whose last frame flows into its first (--seconds: the cycle's length)")
    g.add_argument("--in-place", action="store_true", help="remove the root's horizontal travel (facing kept)")
    g.add_argument("--path", type=Path, default=None,
                   help="JSON list of [x, z] points (metres, Y up) to walk along; the length follows the path "
                        "unless --seconds is given")
    g.add_argument("--speed", type=float, default=None, help="play 0.5 to 2 times as fast (feet re-planted)")
    g.add_argument("--stretch", type=float, default=None, metavar="SECONDS",
                   help="stretch or squeeze the motion to this many seconds (feet re-planted)")


def animation_of(args):
    """The ``Animation`` of parsed arguments (checked before any model loads)."""
    from ..core.generation.animate import Animation, check_animation
    from ..core.generation.path_follow import read_path

    return check_animation(Animation(loop=args.loop, in_place=args.in_place,
                                     path=read_path(args.path) if args.path is not None else None,
                                     speed=args.speed, stretch=args.stretch))


def run(args) -> int:
    from ..core.body.measure import format_body, measure
    from ..core.generation.generate import parse_betas
    from ..core.generation.loaded_generator import loaded_generator

    plan = None
    if getattr(args, "plan", None) is not None:   # an edited plan: its prompt is the one generated
        from ..core.plan.plan import MAX_PLAN_BYTES, plan_from_json

        if args.prompt is not None or args.prompts is not None:
            raise ShapeMoveError("--plan takes the place of --prompt / --prompts: give one of them")
        if not args.plan.is_file():
            raise ShapeMoveError(f"plan file not found: {args.plan}")
        if args.plan.stat().st_size > MAX_PLAN_BYTES:
            raise ShapeMoveError(f"plan file {args.plan} is larger than {MAX_PLAN_BYTES // 1024} KB")
        plan = plan_from_json(args.plan.read_text(encoding="utf-8", errors="replace"), args.seconds)
        args.prompt = plan.segments[0].text if not plan.is_sequence else plan.prompt
        if args.seconds is None and plan.seconds is not None:
            args.seconds = plan.seconds
    if args.explain:   # the plan, without loading any model
        import json

        if args.prompt is None:
            raise ShapeMoveError("--explain shows the plan of one --prompt TEXT")
        from ..core.generation.course_shapes import model_course_seconds
        from ..core.plan.explain import plan_json

        once_round = model_course_seconds(args.model)   # a course's segment: the model's typical pace, no torch
        if plan is not None:
            from ..core.plan.plan import plan_to_json

            shown = plan_to_json(plan, once_round)
        else:
            shown = plan_json(args.prompt, args.seconds, loop=args.loop, in_place=args.in_place,
                              path=args.path is not None, by_parts=not args.no_parts, course_seconds=once_round)
        if args.out is not None:   # kept to edit and generate from (--plan)
            from ..core.atomic import atomic_write_json

            if args.out.suffix.lower() != ".json":
                raise ShapeMoveError(f"with --explain, --out is the plan file to write (.json), got {args.out}")
            atomic_write_json(ensure_parent(args.out), shown)
            print(f"wrote the plan to {args.out} (edit it, then: generate --plan {args.out} --out OUT.npz)")
        else:
            print(json.dumps(shown, indent=2))
        return 0
    if args.out is None:
        raise ShapeMoveError("give the motion file to write with --out OUT.npz (or --explain to see the plan only)")
    if args.prompt is None and args.prompts is None and getattr(args, "plan", None) is None:
        raise ShapeMoveError("give --prompt TEXT, --plan PLAN.json (one motion) or --prompts FILE (a batch)")
    if args.prompts is not None:
        from .generate_batch import run_generate_batch

        return run_generate_batch(args)
    if args.prompt is None:
        raise ShapeMoveError("give --prompt TEXT (one motion) or --prompts FILE (a batch)")
    if args.out.suffix.lower() != ".npz":
        raise ShapeMoveError(f"--out must end in .npz, got {args.out}")
    check_sampling(args.seed, args.temperature, args.top_k)  # before loading any model
    from ..core.generation.sampling_params import (DEFAULT_CANDIDATES, DEFAULT_RETRIEVAL_FIRST, DEFAULT_RETRIEVAL_PREFIX,
                                                   DEFAULT_RETRIEVED, check_candidates, check_guidance,
                                                   check_retrieval_first, check_retrieval_prefix, check_retrieved)

    candidates = check_candidates(DEFAULT_CANDIDATES if args.candidates is None else args.candidates)
    retrieved = check_retrieved(DEFAULT_RETRIEVED if args.retrieved is None else args.retrieved)
    first = check_retrieval_first(DEFAULT_RETRIEVAL_FIRST if args.retrieval_first is None else args.retrieval_first)
    prefix = check_retrieval_prefix(DEFAULT_RETRIEVAL_PREFIX if args.retrieval_prefix is None else args.retrieval_prefix)
    guidance = check_guidance(args.guidance)
    ensure_parent(args.out)  # a parent that is a file, or no permission: said now, not after generating
    betas = parse_betas(args.betas) if args.betas else None
    animation = animation_of(args)
    gen = loaded_generator(args.model, args.body_model, args.library)
    gen.set_retrieval(not args.no_retrieval)
    gen.set_captured(not args.no_library)
    if args.library is not None:
        print(f"retrieval memory: {len(gen.library_files)} motions added from {args.library}")
    from ..core.generation.animate import animate
    from ..core.generation.generate import Request

    motion = animate(gen, Request(args.prompt, args.shape_text, betas, args.seconds, args.seed, args.temperature,
                                  args.top_k, args.shape_from, candidates, guidance, prefix, retrieved, first,
                                  not args.no_parts, plan=plan), animation)
    save_motion(args.out, motion)
    import sys

    for n in motion.notes:  # a library clip played as captured
        print(f"note: {n}")
    for w in motion.warnings:  # a prompt far from the training captions
        print(f"warning: {w}", file=sys.stderr)
    m = measure(gen.body, motion.betas)
    ik = "" if motion.ik_error_cm is None else f", IK error {motion.ik_error_cm:.2f} cm"
    print(f"wrote {args.out}: {motion.num_frames} frames ({motion.num_frames / motion.fps:.1f} s), "
          f"{motion.num_tokens} tokens{ik}")
    if not args.no_parts:
        from ..core.plan.explain import plan_lines

        for line in plan_lines(args.prompt, motion, plan):
            print(line)
    if motion.provenance:   # "captured: HDM05 bd kickLFront 003 (CC BY-SA 3.0)" or "generated"
        print(motion.provenance)
    if motion.part_prompts:
        print(f"two things at once: legs {motion.part_prompts[0]!r}, arms {motion.part_prompts[1]!r}"
              + (" (arms mirrored to the named side)" if motion.arms_mirrored else ""))
    elif motion.mirrored:
        print("mirrored: the named side now moves most")
    if motion.retrieved_clips and "captured:" not in (motion.provenance or ""):
        print(f"kept a retrieved clip: {', '.join(motion.retrieved_clips)}")
    if motion.loop_advance is not None:
        print(f"loop: the root advances {float(np.linalg.norm(motion.loop_advance[[0, 2]])):.2f} m per cycle")
    print(f"body ({motion.shape_source or '[BETA] head'}): " + format_body(m))
    if (motion.shape_source or "[BETA] head") == "[BETA] head":
        said = gen.head_reading(args.prompt, args.shape_text)
        if said:
            print(f"  the [BETA] head read: {said}")
    return 0
