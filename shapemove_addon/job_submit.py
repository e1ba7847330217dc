"""Submit a ShapeMove job from an operator: make the panel ops known to an in-process runner,
pick a worker Python when Blender's has no torch, and remember which job each panel runs.

    jid = submit_job("generate", params, kind="generate", on_result=..., on_error=...)
"""
from __future__ import annotations

from . import jobs
from ..core.errors import ShapeMoveError
from ..core.worker import ops
from .paths import detect_python
from .preferences import preferences

RUNNING: dict[str, str] = {}  # panel kind ("generate", "train", ...) -> its running job id


def _ensure_ops() -> None:
    """The in-process runner serves ``core.worker.ops.JOBS``: add the panel ops to it."""
    from ..core.worker.jobs_animation import OPS as animation_ops
    from ..core.worker.jobs_shapemove import register

    register(ops.JOBS)
    ops.JOBS.update(animation_ops)


def _auto_python() -> bool:
    """Fill an empty 'Python environment' preference with a detected Python that has torch."""
    prefs = preferences()
    if prefs is None or prefs.python_env or jobs.python_setting():
        return False
    try:
        found = detect_python()
    except ShapeMoveError:
        return False
    if not found:
        return False
    prefs.python_env = found  # the job manager starts a runner on the new Python at the next submit
    return True


def submit_job(op: str, params: dict, *, kind: str | None = None, label: str | None = None, on_result=None,
               on_error=None, on_progress=None) -> str:
    """Start ``op`` -> job id; raises ShapeMoveError when no runner can be set up."""
    _ensure_ops()
    mgr = jobs.manager()

    def done(callback):
        def call(msg):
            if kind is not None and RUNNING.get(kind) == msg.get("id"):
                del RUNNING[kind]
            if callback is not None:
                callback(msg)
        return call

    def popup(msg):
        jobs.report_error(f"{label or op} failed: {msg['message']}")

    kw = dict(label=label or op, on_result=done(on_result), on_error=done(on_error or popup), on_progress=on_progress)
    try:
        jid = mgr.submit(op, params, **kw)
    except ShapeMoveError:
        if not _auto_python():
            raise
        jid = mgr.submit(op, params, **kw)
    if kind is not None:
        RUNNING[kind] = jid
    return jid


def running(kind: str) -> bool:
    return kind in RUNNING and RUNNING[kind] in jobs.manager().jobs


def cancel(kind: str) -> bool:
    jid = RUNNING.get(kind)
    if jid is None:
        return False
    jobs.manager().cancel(jid)
    return True
