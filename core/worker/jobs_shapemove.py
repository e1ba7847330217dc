"""The job ops behind the Blender panels (pure core code, no bpy): generate, redecode, retarget,
search, train, betas_from_text (and measure, which ``ops`` already serves).

Each op is ``op(params, progress, cancel) -> dict`` (JSON-able); files are handed over by path:
the UI passes an ``out`` path (.npz) under its data folder and builds the rig from the file the
op wrote (atomically). ``register(JOBS)`` adds the ops to a registry (core/worker/ops.py's JOBS).
One generator is kept loaded per process (``generation/loaded_generator.py``) so a long-lived worker
answers fast.
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from ..generation.loaded_generator import loaded_generator
from ..generation.model_bundle import part_warnings
from ..scene.motion_file import load_motion, save_motion
from ..search.motion_search import check_query, index_library, library_clip, search as _search
from .op_support import JobCancelled, param

TRAIN_KINDS = ("vae", "t5", "tma")


# -- helpers -----------------------------------------------------------------------------------
def _out_path(params: dict, op: str) -> Path:
    out = Path(param(params, op, "out", str))
    if out.suffix.lower() != ".npz":
        raise ShapeMoveError(f"op {op!r}: 'out' must be a .npz path, got {out}")
    return out


def _betas(params: dict, op: str, name: str = "betas", default=None):
    value = param(params, op, name, list, default)
    if value is None:
        return None
    try:
        b = np.asarray(value, dtype=np.float32).reshape(-1)
    except (TypeError, ValueError):
        raise ShapeMoveError(f"op {op!r}: {name!r} must be a list of 10 numbers") from None
    if b.shape != (10,) or not np.isfinite(b).all():
        raise ShapeMoveError(f"op {op!r}: {name!r} must be 10 finite numbers, got {b.shape[0]}")
    return b


def _generator(model, body, library=None):
    """The process's loaded Generator for (model folder or None = default, body spec, library folder
    or None) (``generation.loaded_generator``)."""
    return loaded_generator(model, body, library)


def _measurements(body, betas) -> dict:
    from ..body.measure import measure

    try:
        return {k: round(float(v), 1) for k, v in measure(body, betas).items()}
    except ShapeMoveError:
        return {}


PANEL_PHYSICS = ("penetrate_cm", "float_cm", "skate_pct", "dyn_stable_pct")  # what the Generate panel shows


def _physics(body, motion) -> dict:
    """The motion's physics figures on its own body (core/eval: mesh penetration and floating in
    cm, foot skating in % of frames, dynamic stability in % of frames); {} if they cannot be had."""
    from ..eval.generate_eval import physics

    try:
        res = physics(body, motion.betas, motion.poses, motion.transl)
    except ShapeMoveError:
        return {}
    return {k: round(float(res[k]), 3) for k in PANEL_PHYSICS if np.isfinite(res.get(k, np.nan))}


def _motion_facts(path: Path, motion) -> dict:
    return {"path": str(path), "frames": motion.num_frames, "fps": float(motion.fps),
            "betas": [float(b) for b in motion.betas], "body_model": motion.body_model,
            "tokens": 0 if motion.tokens is None else int(len(motion.tokens))}


# -- ops ---------------------------------------------------------------------------------------
def generate(params, progress, cancel) -> dict:
    """params {"prompt", "shape_text", "betas" (10, optional), "seconds" (optional), "seed",
    "temperature", "top_k", "by_parts" (optional, default true), "model" (folder, optional), "body",
    "library" (optional: a folder of the user's captioned motions added to the retrieval memory; a
    clip of it kept whose codes miss it is played as captured, ``library_takes.py``), "captured"
    (optional, default true: captured takes compete, ``captured_takes.py``), "plan" (optional: an
    edited plan, the JSON ``generate --explain`` prints, generated from in place of "prompt";
    ``plan/plan.py``), "out" (.npz)}
    -> the motion file written, its facts, the body's measurements (cm), what generation by body
    part did ("parts") and the plan it was made from ("plan", JSON)."""
    from ..generation.generate import Request

    op = "generate"
    out = _out_path(params, op)
    plan = None
    if params.get("plan") is not None:   # the panel's edited plan (plan/panel_fields.py)
        from ..plan.plan import plan_from_json

        plan = plan_from_json(param(params, op, "plan", str), param(params, op, "seconds", (int, float), None))
        params = {**params, "prompt": plan.segments[0].text if not plan.is_sequence else plan.prompt,
                  "seconds": plan.seconds if plan.seconds is not None else params.get("seconds")}
    req = Request(prompt=param(params, op, "prompt", str), shape_text=param(params, op, "shape_text", str, None) or None,
                  betas=_betas(params, op), seconds=param(params, op, "seconds", (int, float), None),
                  seed=int(param(params, op, "seed", int, 0)),
                  temperature=float(param(params, op, "temperature", (int, float), 1.0)),
                  top_k=param(params, op, "top_k", int, 50))
    if params.get("candidates") is not None:
        req.candidates = param(params, op, "candidates", int)
    if params.get("guidance") is not None:
        req.guidance = float(param(params, op, "guidance", (int, float)))
    req.by_parts = bool(param(params, op, "by_parts", bool, True))
    req.plan = plan
    progress(0.05, "loading models")
    gen = _generator(param(params, op, "model", str, None), param(params, op, "body", str, None),
                     param(params, op, "library", str, None))
    gen.set_captured(bool(param(params, op, "captured", bool, True)))
    if cancel():
        raise JobCancelled
    progress(0.2, "writing motion tokens")
    motions = gen.generate_batch([req], cancel=cancel)
    if not motions:
        raise JobCancelled
    save_motion(out, motions[0])
    progress(0.9, "checking the physics")
    phys = _physics(gen.body, motions[0])
    progress(1.0, "done")
    check = motions[0].prompt_check
    return {**_motion_facts(out, motions[0]), "measurements": _measurements(gen.body, motions[0].betas),
            "physics": phys, "ik_error_cm": float(motions[0].ik_error_cm or 0.0),
            "warnings": list(motions[0].warnings),
            "model_warnings": [w for w in motions[0].warnings if w in part_warnings(gen.model_dir)],
            "nearest_actions": list(check.nearest_actions) if check is not None else [],
            "parts": _parts(motions[0]), "notes": list(motions[0].notes), "provenance": motions[0].provenance,
            "plan": motions[0].plan}


def _parts(motion) -> list[str]:
    """What generation by body part did, in a line each ([] when the prompt was generated whole)."""
    out = []
    if motion.part_prompts:
        out.append(f"Two things at once: legs '{motion.part_prompts[0]}', arms '{motion.part_prompts[1]}'")
    if motion.mirrored or motion.arms_mirrored:
        out.append("Mirrored so the side you named moves most")
    return out


def redecode(params, progress, cancel) -> dict:
    """params {"motion" (.npz with tokens, a take played by its own rotations or a loop), "betas" (10), "model",
    "body", "out"} -> the same tokens decoded for the new body (a take: planted again on it,
    ``retarget.replant``), written to ``out``."""

    op = "redecode"
    out = _out_path(params, op)
    betas = _betas(params, op)
    if betas is None:
        raise ShapeMoveError("op 'redecode': missing parameter 'betas'")
    motion = load_motion(param(params, op, "motion", str))
    gen = _generator(param(params, op, "model", str, None), param(params, op, "body", str, None))
    progress(0.3, "decoding")
    new = gen.redecode(motion, betas)
    save_motion(out, new)
    return _motion_facts(out, new)


def retarget(params, progress, cancel) -> dict:
    """params {"source" (BVH / ASF+AMC / AMASS .npz), "body", "betas" (10, optional: else the
    source subject's own shape, fitted to its bone lengths), "source_fps" / "angle_unit" (optional
    overrides of what the file declares: ``io.mocap.reader_options``), "method" ("auto" | "savae" | "naive";
    auto = through the SA-VAE when a model has one and its codes carry the take
    (``take_fidelity.LOST_TAKE_MM``), else the take's own rotations with its feet planted
    (``planted_retarget``), or naive without a model; "savae" = through the SA-VAE whatever it
    loses), "search" (optional, default true:
    the SA-VAE's codes searched for on the subject's body), "model", "out"} -> the motion on
    the body, written to ``out``."""
    from ..body.fit import bone_lengths, fit_betas_to_bone_lengths
    from ..body.load import load_body_model
    from ..generation.retarget import load_vae, naive_retarget, retarget as savae_retarget, source_joints
    from ..generation.take_fidelity import LOST_TAKE_MM

    op = "retarget"
    out = _out_path(params, op)
    source = Path(param(params, op, "source", str))
    if not source.is_file():
        raise ShapeMoveError(f"op 'retarget': source file not found: {source}")
    method = param(params, op, "method", str, "auto")
    if method not in ("auto", "savae", "naive"):
        raise ShapeMoveError(f"op 'retarget': method must be auto, savae or naive, got {method!r}")
    body = load_body_model(param(params, op, "body", str, None))
    progress(0.1, f"reading {source.name}")
    source = library_clip(source)
    read = {k: v for k, v in (("source_fps", param(params, op, "source_fps", (int, float), None)),
                              ("angle_unit", param(params, op, "angle_unit", str, None))) if v is not None}
    joints, _ = source_joints(source, body, read)
    betas = _betas(params, op)
    if betas is None:  # the subject's own proportions
        betas = fit_betas_to_bone_lengths(body, np.median(bone_lengths(joints), axis=0)).betas
    vae = None
    if method != "naive":
        try:
            vae = load_vae(param(params, op, "model", str, None), body)
        except ShapeMoveError:
            if method == "savae":
                raise
    if cancel():
        raise JobCancelled
    progress(0.3, "retargeting" + (" through the SA-VAE" if vae is not None else " (naive: no SA-VAE model)"))
    def searching(fraction):
        if cancel():
            raise JobCancelled
        progress(0.3 + 0.6 * fraction, "retargeting through the SA-VAE: searching codes")

    motion = (savae_retarget(source, vae, body, betas, read=read, search=param(params, op, "search", bool, True),
                             progress=searching, fallback_mm=LOST_TAKE_MM if method == "auto" else None)
              if vae is not None else naive_retarget(source, body, betas, read=read))
    motion.prompt = motion.prompt or (source.subject if not isinstance(source, Path) else source.stem)
    save_motion(out, motion)
    used = "naive" if vae is None else ("planted" if motion.tokens is None else "savae")
    return {**_motion_facts(out, motion), "method": used, "notes": list(motion.notes)}


def search(params, progress, cancel) -> dict:
    """params {"folder", "query", "top_k", "tma" (tma.pt or a folder holding it, optional)} ->
    {"results": [{"id", "score", "path", "caption"}], "count", "skipped", "from_cache"}."""
    op = "search"
    query = check_query(param(params, op, "query", str), int(param(params, op, "top_k", int, 10)))
    index = index_library(param(params, op, "folder", str), tma=param(params, op, "tma", str, None) or None,
                          progress=lambda f, m="": progress(0.9 * f, m))
    hits = _search(index, query, int(param(params, op, "top_k", int, 10)))
    return {"results": [{"id": i, "score": s, "path": p, "caption": c} for i, s, p, c in hits],
            "count": len(index), "skipped": len(index.skipped), "from_cache": index.from_cache}


def _publish(src: Path, dst: Path) -> None:
    """Copy a file or folder to ``dst`` (replacing it) via a temporary name beside it."""
    tmp = dst.with_name(dst.name + ".tmp")
    if tmp.exists():
        shutil.rmtree(tmp) if tmp.is_dir() else tmp.unlink()
    dst.parent.mkdir(parents=True, exist_ok=True)
    if src.is_dir():
        shutil.copytree(src, tmp)
        if dst.exists():
            shutil.rmtree(dst)
        os.replace(tmp, dst)
    else:
        shutil.copy2(src, tmp)
        os.replace(tmp, dst)


def train(params, progress, cancel) -> dict:
    """params {"kind": "vae" | "t5" | "tma", "data" (dataset folder), "model_dir" (the model folder
    being built: savae.pt, t5/, tma/), "steps", "resume", "device", "config" ("small" | "paper" |
    "tiny" | JSON path), "body"}. Trains in ``model_dir/runs/<kind>``; a run that finished (not
    cancelled) is copied into the model folder's layout. Cancel stops after saving last.pt."""
    op = "train"
    kind = param(params, op, "kind", str)
    if kind not in TRAIN_KINDS:
        raise ShapeMoveError(f"op 'train': kind must be one of {', '.join(TRAIN_KINDS)}, got {kind!r}")
    data = Path(param(params, op, "data", str))
    if not data.is_dir():
        raise ShapeMoveError(f"op 'train': dataset folder not found: {data} (build one with `python -m shapemove data build`)")
    model_dir = Path(param(params, op, "model_dir", str))
    run = model_dir / "runs" / kind
    steps = param(params, op, "steps", int, None)
    resume = bool(param(params, op, "resume", bool, False)) and (run / "last.pt").is_file()
    device = param(params, op, "device", str, None)
    config = param(params, op, "config", str, "small")
    body = param(params, op, "body", str, None)
    kw = dict(steps=steps, resume=resume, device=device, progress=progress, cancel=cancel, verbose=False)
    if kind == "vae":
        from ..models.savae import SAVAEConfig
        from ..train.train_vae import train_vae

        metrics = train_vae(data, run, SAVAEConfig.load(config), body=body, **kw)
        product, target = run / "savae.pt", model_dir / "savae.pt"
    elif kind == "t5":
        from ..train.train_t5 import T5TrainConfig, train_t5

        vae = model_dir / "savae.pt"
        if not vae.is_file():
            raise ShapeMoveError(f"op 'train': T5 training needs the SA-VAE first ({vae}): train kind 'vae' into this model")
        metrics = train_t5(data, vae, run, T5TrainConfig.load(config), **kw)
        product, target = run / "t5", model_dir / "t5"
    else:
        from ..train.train_tma import train_tma

        metrics = train_tma(data, run, config, body=body, **kw)
        product, target = run, model_dir / "tma"
    published = False
    if not cancel() and product.exists():
        if kind == "tma":  # tma.pt, and the tokenizer/ of a sentencepiece TMA beside it (MiniLM TMAs have none)
            target.mkdir(parents=True, exist_ok=True)
            _publish(run / "tma.pt", target / "tma.pt")
            if (run / "tokenizer").is_dir():
                _publish(run / "tokenizer", target / "tokenizer")
        else:
            _publish(product, target)
        published = True
    return {"kind": kind, "run": str(run), "model_dir": str(model_dir), "published": published,
            "metrics": metrics, "resumable": (run / "last.pt").is_file()}


def betas_from_text(params, progress, cancel) -> dict:
    """params {"text": shape text ("a tall, heavy-set man", "an elderly woman, 160 cm, 70 kg",
    "standing 185 cm tall, with a waist circumference of 90 cm"), "body"} -> {"betas": 10 numbers,
    "measurements": the targets (cm, kg), "achieved": measured on the result (cm, kg, BMI)}."""
    from ..body.load import load_body_model
    from ..body.shape_from_measurements import betas_from_shape_text, targets_from_shape_text

    op = "betas_from_text"
    text = param(params, op, "text", str)
    body = load_body_model(param(params, op, "body", str, None))
    wanted = targets_from_shape_text(text, body)
    betas = np.asarray(betas_from_shape_text(body, text), np.float32).reshape(-1)  # words set the sliders too
    return {"betas": betas.tolist(), "measurements": wanted, "achieved": _measurements(body, betas)}


OPS = {"generate": generate, "redecode": redecode, "retarget": retarget, "search": search, "train": train,
       "betas_from_text": betas_from_text}


def register(jobs: dict) -> dict:
    """Add these ops to the ``jobs`` registry (existing entries of other names are kept)."""
    jobs.update(OPS)
    return jobs
