"""The item task of ``generate --prompts`` (motions only, no Blender): an item's options and the
batch's settings to a motion file ``{stem}.npz``. Each process keeps its loaded generator
(``generation/loaded_generator.py``), so a worker loads the model once; a lock lets a
multi-threaded Dask worker share it."""
from __future__ import annotations

import threading
from pathlib import Path

from ..scene.motion_file import save_motion

LOCK = threading.Lock()   # held around an item's generation (a Dask worker may run items on threads)


def generator_for(where: dict, retrieval: bool = True, captured: bool = True):
    """The process's generator for ``where`` ({"model", "body_model", "library"} paths or None):
    the one ``loaded_generator`` keeps, with retrieval and captured takes as the batch's settings
    say (``--no-retrieval``, ``--no-library``)."""
    from ..generation.loaded_generator import loaded_generator

    def said(gen, clips):
        if clips is not None:
            print(f"retrieval memory: {clips} motions added from {where['library']}")

    gen = loaded_generator(where.get("model"), where.get("body_model"), where.get("library"), on_load=said)
    gen.set_retrieval(retrieval)
    gen.set_captured(captured)
    return gen


def warm_generator(where: dict) -> None:
    """Load the generator for ``where`` and what it reads on first use (the TMA that picks, the
    captured takes, the standing code), so processes forked from this one start warm
    (``engines.ProcessPool(preload=...)``)."""
    gen = generator_for(where)
    _ = gen.picker, gen.pool, gen.rest_code, gen.typical_speeds


def item_motion(spec: dict):
    """(Motion, Generator) of one item (``spec``: options + settings, see manifest.py)."""
    import numpy as np

    from ..generation.animate import Animation, animate
    from ..generation.in_place import in_place
    from ..generation.request import Request
    from ..generation.sequence import generate_sequence

    o, s = spec["options"], spec["settings"]
    gen = generator_for(spec["where"], s["retrieval"], s.get("captured", True))
    betas = np.asarray(o["betas"], np.float32) if o.get("betas") is not None else None
    if o.get("sequence"):
        motion = generate_sequence(gen, [(x["prompt"], x["seconds"]) for x in o["sequence"]], o.get("shape_text"),
                                   betas, o["seed"], s["temperature"], s["top_k"], s["candidates"], s["guidance"],
                                   by_parts=s["parts"])
        return (in_place(motion) if o.get("in_place") else motion), gen
    req = Request(o["prompt"], o.get("shape_text"), betas, o.get("seconds"), o["seed"], s["temperature"], s["top_k"],
                  s["shape_from"], s["candidates"], s["guidance"], s["retrieval_prefix"], s["retrieved"],
                  s["retrieval_first"], s["parts"])
    anim = Animation(loop=o["loop"], in_place=o["in_place"],
                     path=np.asarray(o["path"], np.float64) if o.get("path") is not None else None,
                     speed=o.get("speed"), stretch=o.get("stretch"))
    return animate(gen, req, anim), gen


def motion_facts(motion) -> dict:
    """{"source", "result"} of a motion for its manifest line."""
    provenance = getattr(motion, "provenance", None) or ""
    kind = "captured" if "captured:" in provenance else "retrieved" if motion.retrieved_clips else "generated"
    source = {"kind": kind, "provenance": getattr(motion, "provenance", None), "retrieved_clips": list(motion.retrieved_clips), "notes": list(motion.notes),
              "warnings": list(motion.warnings), "part_prompts": list(motion.part_prompts or []) or None,
              "mirrored": bool(motion.mirrored)}
    result = {"frames": int(motion.num_frames), "seconds": round(motion.num_frames / motion.fps, 3),
              "betas": [round(float(b), 6) for b in motion.betas], "shape_source": motion.shape_source,
              "ik_error_cm": None if motion.ik_error_cm is None else round(float(motion.ik_error_cm), 4)}
    return {"source": source, "result": result}


def generate_item(spec: dict, folder: Path) -> dict:
    with LOCK:
        motion, _ = item_motion(spec)
        name = spec["stem"] + ".npz"
        save_motion(Path(folder) / name, motion)
    return {"files": [name], **motion_facts(motion)}
