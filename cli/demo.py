"""`python -m shapemove demo [--prompt TEXT] [--shape-text TEXT] [--out DIR]`: the one-command demo.

Generates the prompt with the embedded default model on OpenBody (the body of the shape text, else
of the prompt's person words, else "a tall, heavy-set man"), builds the scene headless and
writes ``DIR/shapemove.blend``, ``DIR/preview.png`` (a strip of frames) and ``DIR/motion.npz``,
then prints where they are and the predicted body measurements.
"""
from __future__ import annotations

from pathlib import Path

from ..core.data.shape_text import shape_adjectives
from ..core.errors import ShapeMoveError
from ..core.plan.explain import plan_lines
from ..core.scene.motion_file import save_motion

DEFAULT_PROMPT = "a person jogs forward and waves"
DEFAULT_SHAPE = "a tall, heavy-set man"


def add_arguments(p):
    p.add_argument("--prompt", default=DEFAULT_PROMPT)
    p.add_argument("--shape-text", default=None,
                   help=f"the body (default: the prompt's person words, \"{DEFAULT_SHAPE}\" when it names none)")
    p.add_argument("--seconds", type=float, default=None)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--model", type=Path, default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--out", type=Path, default=Path("out/demo"))
    p.add_argument("--frames", type=int, default=5, help="frames in the preview strip")


def demo_shape(body, prompt: str, shape_text: str | None) -> str | None:
    """The shape text the demo generates with: the one given; none when the prompt's person words
    say who ("a short, stocky woman picks up a box": the body from them, as ``generate`` does);
    else ``DEFAULT_SHAPE``."""
    from ..core.generation.generate import body_from_prompt

    if shape_text and shape_text.strip():
        return shape_text
    return None if body_from_prompt(body, prompt)[1] == "prompt words" else DEFAULT_SHAPE


def run(args) -> int:
    import time

    from ..core.body.measure import format_body, measure
    from ..core.generation.loaded_generator import loaded_generator

    t0 = time.time()
    gen = loaded_generator(args.model)
    shape = demo_shape(gen.body, args.prompt, args.shape_text)
    motion = gen.generate(args.prompt, shape, seconds=args.seconds, seed=args.seed)
    save_motion(args.out / "motion.npz", motion)
    t1 = time.time()
    try:
        from ..shapemove_addon.headless import build_scene_file
    except ImportError:
        raise ShapeMoveError("the demo needs the bpy module (make setup installs it)") from None
    info = build_scene_file(motion, gen.body, args.out / "shapemove.blend", args.out / "preview.png", frames=args.frames)
    m = measure(gen.body, motion.betas)
    print(f"prompt:      {motion.prompt}")
    print(f"shape text:  {shape or '(none: the prompt says who)'}  (body from: {motion.shape_source or '[BETA] head'})")
    if motion.provenance:   # "captured: HDM05 bd kickLFront 002 (CC BY-SA 3.0)", "generated", per segment
        print(f"source:      {motion.provenance}")
    print(f"motion:      {motion.num_frames} frames at {motion.fps:g} fps ({motion.num_frames / motion.fps:.1f} s), "
          f"{motion.num_tokens} tokens, generated in {t1 - t0:.1f} s")
    if motion.part_prompts:
        print(f"by part:     legs {motion.part_prompts[0]!r}, arms {motion.part_prompts[1]!r}")
    for line in plan_lines(args.prompt, motion):
        print(line)
    for n in motion.notes:
        print(f"note: {n}")
    print(f"body:        {shape_adjectives(m, _sex(gen.body, motion.betas))}: " + format_body(m))
    print(f"scene:       {(args.out / 'shapemove.blend').resolve()}  ({info['vertices']} vertices, {info['bones']} bones, "
          f"frames {info['frame_start']}-{info['frame_end']})")
    print(f"preview:     {(args.out / 'preview.png').resolve()}  (frames {info['preview_frames']})")
    print(f"motion file: {(args.out / 'motion.npz').resolve()}")
    return 0


def _sex(body, betas) -> str | None:
    """"male" / "female" when the body's gender slider, read back from its betas through the body
    model's phenotype map, is at most 0.25 / at least 0.75 (the shape-words evaluation's bands); else None."""
    pmap = getattr(body, "phenotype_map", None)
    if pmap is None:
        return None
    g = float(dict(zip(pmap.names, pmap.from_betas(betas)))["gender"])
    return "male" if g <= 0.25 else "female" if g >= 0.75 else None
