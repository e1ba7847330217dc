"""The job ops the worker serves: ``JOBS[name](params, progress, cancel) -> dict`` (JSON-able).

``progress(fraction, message)`` reports 0..1; ``cancel()`` is true once the caller cancelled (stop
soon and return what you have). Bad params -> ShapeMoveError naming the op and the parameter.
Heavy imports (torch, the models) happen inside each op, so the worker starts fast.
To add an op: write ``def my_op(params, progress, cancel) -> dict`` next to the code it runs and add
one line to ``JOBS`` below (or call ``register("name", func)`` before the worker serves). The
panel ops of ``jobs_shapemove`` join through ``default_jobs()``, which the runners use.
"""
from __future__ import annotations

import sys
from pathlib import Path

from ... import __version__
from ..errors import ShapeMoveError
from .op_support import param, str_list
from .protocol import CONTROL_OPS

# -- ops ---------------------------------------------------------------------------------------
def env_info(params, progress, cancel) -> dict:
    """Facts about the Python that runs the jobs (torch version, CUDA) - the UI's environment check."""
    import platform

    import numpy
    import torch

    return {"executable": sys.executable, "python": platform.python_version(), "platform": platform.platform(),
            "shapemove": __version__, "numpy": numpy.__version__, "torch": torch.__version__,
            "cuda": bool(torch.cuda.is_available()), "threads": torch.get_num_threads()}


def body_info(params, progress, cancel) -> dict:
    """params {"body": "openbody" | path to an SMPL-family file (default openbody)} -> model facts;
    height_m is the rest-pose height at betas 0 (top minus lowest vertex, metres)."""
    from ..body.load import load_body_model

    body = load_body_model(param(params, "body_info", "body", str, None))
    verts = body.rest_vertices(None)[0].numpy()
    out = {"name": body.name, "num_vertices": body.num_vertices, "num_faces": int(len(body.faces)),
           "num_joints": len(body.parents), "num_betas": body.num_betas, "joint_names": list(body.joint_names),
           "height_m": float(verts[:, 1].max() - verts[:, 1].min())}
    if hasattr(body, "phenotype_names"):
        out["phenotype_names"] = list(body.phenotype_names)
    return out


def measure(params, progress, cancel) -> dict:
    """params {"betas": 10 numbers (default zeros) or B lists of 10, "body"} -> measurements in cm
    (core.body.measure; mass_kg in kg from the mesh volume, bmi in kg/m^2): numbers, or lists of B numbers."""
    from ..body.load import load_body_model
    from ..body.measure import measure as _measure

    import numpy as np

    betas = param(params, "measure", "betas", list, None)
    if betas is not None:
        try:
            betas = np.asarray(betas, np.float64)
        except (TypeError, ValueError):
            raise ShapeMoveError("op 'measure': parameter 'betas' must be a list of numbers "
                                 "(or of lists of numbers)") from None
    body = load_body_model(param(params, "measure", "body", str, None))
    return {k: np.asarray(v).tolist() for k, v in _measure(body, betas).items()}


def build_dataset(params, progress, cancel) -> dict:
    """params {"sources": [paths], "out": path, "body", "augment_share", "limit", "only": [ids]}
    -> the build report (core.data.build). Cancel stops after the current clip (resumable)."""
    import dataclasses

    from ..body.load import load_body_model
    from ..data.build import AUGMENT_SHARE, build_dataset as _build

    op = "build_dataset"
    sources = [Path(s) for s in str_list(params, op, "sources")]
    body = load_body_model(param(params, op, "body", str, None))
    report = _build(sources, Path(param(params, op, "out", str)), body=body,
                    augment_share=float(param(params, op, "augment_share", (int, float), AUGMENT_SHARE)),
                    limit=param(params, op, "limit", int, None), only=str_list(params, op, "only", None),
                    progress=progress, cancel=cancel, verbose=False)
    return {**dataclasses.asdict(report), "summary": report.summary()}


def train_vae(params, progress, cancel) -> dict:
    """params {"data": dataset folder, "out": run folder, "config": "small" | "paper" | JSON path |
    object of overrides (with "base"), "steps", "resume", "body", "device"} -> last metrics.
    Cancel stops after saving last.pt (resume with "resume": true)."""
    from ..models.savae import SAVAEConfig
    from ..train.train_vae import train_vae as _train

    op = "train_vae"
    cfg = param(params, op, "config", (str, dict), "small")
    cfg = SAVAEConfig.from_dict(cfg) if isinstance(cfg, dict) else SAVAEConfig.load(cfg)
    metrics = _train(param(params, op, "data", str), param(params, op, "out", str), cfg,
                     steps=param(params, op, "steps", int, None), resume=param(params, op, "resume", bool, False),
                     body=param(params, op, "body", str, None), device=param(params, op, "device", str, None),
                     progress=progress, cancel=cancel, verbose=False)
    return {"metrics": metrics, "out": param(params, op, "out", str)}


JOBS: dict = {
    "env_info": env_info,
    "body_info": body_info,
    "measure": measure,
    "build_dataset": build_dataset,
    "train_vae": train_vae,
}


_PANEL_OPS: list[str] = []  # "" once added, else why they could not be


def default_jobs() -> dict:
    """JOBS plus the ops behind the Blender panels (``jobs_shapemove``: generate, retarget, train,
    search, ...), added on first use. In a Python that cannot import them: JOBS alone, and
    ``panel_ops_problem()`` says why."""
    if not _PANEL_OPS:
        try:
            from .jobs_animation import OPS as animation_ops  # loop, path, timeline (docs/animation.md)
            from .jobs_shapemove import register as add_panel_ops

            add_panel_ops(JOBS)
            JOBS.update(animation_ops)
            _PANEL_OPS.append("")
        except ModuleNotFoundError as exc:
            _PANEL_OPS.append(f"the panel ops (generate, train, ...) need the Python package {exc.name!r}, "
                              f"which is not installed in {sys.executable}")
    return JOBS


def panel_ops_problem() -> str:
    return _PANEL_OPS[0] if _PANEL_OPS else ""


def register(name: str, func) -> None:
    """Add a job op (``func(params, progress, cancel) -> dict``); control op names are reserved."""
    if name in CONTROL_OPS:
        raise ShapeMoveError(f"{name!r} is a control op of the worker and cannot be a job")
    JOBS[name] = func
