"""Worker ops of the animation features (docs/animation.md), for the Blender panel:

- ``animate``: the ``generate`` op's params (with "library": the user's captioned motions compete,
  one the codes cannot carry is played as captured) plus "loop", "in_place", "path" ([[x, z], ...]
  metres, Y up), "speed", "stretch" -> the motion file written and its facts (with its "notes");
- ``sequence``: {"segments": [{"prompt", "seconds"}, ...], "shape_text", "betas", "seed", "model",
  "body", "out"} -> a timeline motion; with "regenerate": K (0-based) and "motion" (a timeline
  file) segment K is sampled again with "seed" and the others are kept, for the body "betas" (the
  rig's now) or else the file's; "captured" (default true): captured takes compete in each segment
  (``stitched_timeline.py``), false: a timeline of codes.
"""
from __future__ import annotations

from contextlib import contextmanager

from ..errors import ShapeMoveError
from ..scene.motion_file import load_motion, save_motion
from .jobs_shapemove import _betas, _generator, _measurements, _motion_facts, _out_path
from .op_support import JobCancelled, param


def _facts(out, motion, body) -> dict:
    facts = {**_motion_facts(out, motion), "measurements": _measurements(body, motion.betas),
             "ik_error_cm": float(motion.ik_error_cm or 0.0), "warnings": list(motion.warnings),
             "notes": list(motion.notes), "provenance": motion.provenance}
    if motion.loop_advance is not None:
        facts["loop_advance"] = [float(v) for v in motion.loop_advance]
    if motion.segment_bounds is not None:
        facts["segments"] = [{"prompt": p, "start": int(s), "end": int(e)}
                             for p, (s, e) in zip(motion.segment_prompts, motion.segment_bounds)]
    return facts


@contextmanager
def _cancellable(cancel):
    """A ShapeMoveError that the job's own cancel() caused ends the job as cancelled, not as an error."""
    try:
        yield
    except ShapeMoveError as exc:
        if cancel() and "cancelled" in str(exc):
            raise JobCancelled from None
        raise


def _saved(out, motion, body, progress) -> dict:
    """Write the motion file, report the job done, and return its facts."""
    save_motion(out, motion)
    progress(1.0, "done")
    return _facts(out, motion, body)


def animate(params, progress, cancel) -> dict:
    from ..generation.animate import animation_from, animate as _animate
    from ..generation.generate import Request

    op = "animate"
    out = _out_path(params, op)
    options = animation_from({k: params.get(k) for k in ("loop", "in_place", "path", "speed", "stretch")})
    req = Request(prompt=param(params, op, "prompt", str), shape_text=param(params, op, "shape_text", str, None) or None,
                  betas=_betas(params, op), seconds=param(params, op, "seconds", (int, float), None),
                  seed=int(param(params, op, "seed", int, 0)),
                  temperature=float(param(params, op, "temperature", (int, float), 1.0)),
                  top_k=param(params, op, "top_k", int, 50), by_parts=bool(param(params, op, "by_parts", bool, True)))
    progress(0.05, "loading models")
    gen = _generator(param(params, op, "model", str, None), param(params, op, "body", str, None),
                     param(params, op, "library", str, None))
    if cancel():
        raise JobCancelled
    with _cancellable(cancel):
        motion = _animate(gen, req, options, progress=lambda f, m: progress(0.1 + 0.8 * f, m), cancel=cancel)
    return _saved(out, motion, gen.body, progress)


def sequence(params, progress, cancel) -> dict:
    from ..generation.sequence import generate_sequence, regenerate_segment

    op = "sequence"
    out = _out_path(params, op)
    seed = int(param(params, op, "seed", int, 0))
    regen = param(params, op, "regenerate", int, None)
    by_parts = bool(param(params, op, "by_parts", bool, True))
    progress(0.05, "loading models")
    gen = _generator(param(params, op, "model", str, None), param(params, op, "body", str, None))
    gen.set_captured(bool(param(params, op, "captured", bool, True)))   # captured takes compete in each segment
    if regen is not None:
        timeline = load_motion(param(params, op, "motion", str))
        betas = _betas(params, op)
        if betas is not None:   # the rig's body now (Shape sliders moved since it was generated)
            timeline.betas = betas
        motion = regenerate_segment(gen, timeline, regen, seed,
                                    param(params, op, "prompt", str, None) or None,
                                    param(params, op, "seconds", (int, float), None), by_parts=by_parts)
    else:
        segs = param(params, op, "segments", list)
        if not all(isinstance(s, dict) and "prompt" in s and "seconds" in s for s in segs):
            raise ShapeMoveError("op 'sequence': 'segments' must be a list of {\"prompt\", \"seconds\"} objects")
        with _cancellable(cancel):
            motion = generate_sequence(gen, [(s["prompt"], s["seconds"]) for s in segs],
                                       param(params, op, "shape_text", str, None) or None, _betas(params, op), seed,
                                       progress=lambda f, m: progress(0.1 + 0.85 * f, m), cancel=cancel,
                                       by_parts=by_parts)
    return _saved(out, motion, gen.body, progress)


OPS = {"animate": animate, "sequence": sequence}
