"""Run ShapeMove jobs from the UI without blocking it: one ``JobManager`` (``manager()``) holds a
runner - a worker process in the Python set in the add-on preferences ("Python environment", or
the SHAPEMOVE_PYTHON environment variable), else the same jobs in a thread of Blender's Python
when torch imports there - and a ``bpy.app.timers`` function polls it, calls the job's callbacks,
and shows progress (window-manager progress + ``WindowManager.shapemove_status``).

    jobs.manager().submit("body_info", {}, on_result=lambda msg: print(msg["result"]))

Callbacks get the protocol message dict (core/worker/protocol.py). A job without ``on_error``
shows its error in a popup (printed when there is no window).
"""
from __future__ import annotations

import os
import sys
import traceback
from dataclasses import dataclass

import bpy
from bpy.props import FloatProperty, StringProperty

from ..core.worker.client import default_runner
from .preferences import preferences

POLL_INTERVAL = 0.1  # s between timer ticks while jobs run
PYTHON_ENV_VAR = "SHAPEMOVE_PYTHON"


def python_setting(context=None) -> str:
    """The preferences' Python environment (``python_env``), else $SHAPEMOVE_PYTHON, else ""."""
    try:
        prefs = preferences(context)
    except (AttributeError, RuntimeError):
        prefs = None
    return (getattr(prefs, "python_env", "") if prefs else "") or os.environ.get(PYTHON_ENV_VAR, "")


@dataclass
class _Job:
    label: str
    on_result: object = None
    on_error: object = None
    on_progress: object = None
    on_log: object = None
    fraction: float = 0.0


class JobManager:
    """Per-job callbacks over a runner (WorkerClient or InProcessRunner); ``poll`` is the timer."""

    def __init__(self, runner=None):
        self.runner = runner
        self.jobs: dict[str, _Job] = {}
        self.status = ""
        self._progress_shown = False
        self._python = python_setting() if runner is not None else None  # the Python the runner stands for

    @property
    def busy(self) -> bool:
        return bool(self.jobs)

    def submit(self, op: str, params: dict | None = None, *, label: str | None = None, on_result=None,
               on_error=None, on_progress=None, on_log=None) -> str:
        """Start a job (raises ShapeMoveError when no runner can be set up) -> its id."""
        python = python_setting()
        if self.runner is not None and python != self._python:
            self.set_runner(None)  # the Python environment preference changed: start the new one
        if self.runner is None:
            self.runner = default_runner(python)
            self._python = python
        jid = self.runner.submit(op, params)
        self.jobs[jid] = _Job(label or op, on_result, on_error, on_progress, on_log)
        self._set_status(f"{label or op}: started")
        if not bpy.app.timers.is_registered(_tick):
            bpy.app.timers.register(_tick, first_interval=POLL_INTERVAL, persistent=True)
        return jid

    def cancel(self, job_id: str | None = None) -> None:
        """Cancel one job (or all); each still ends with its result/error message."""
        for jid in [job_id] if job_id else list(self.jobs):
            if self.runner is not None:
                self.runner.cancel(jid)

    def set_runner(self, runner=None) -> None:
        """Stop the current runner (its jobs end with an error) and use ``runner`` (None: pick again
        at the next submit, e.g. after the Python environment preference changed)."""
        old, self.runner, self._python = self.runner, None, None
        if old is not None:
            old.stop()
            for msg in old.poll():
                self._dispatch(msg)
        self.runner = runner
        if runner is not None:  # kept until the Python environment preference changes
            self._python = python_setting()

    # -- timer --------------------------------------------------------------------------------
    def poll(self) -> float | None:
        """Dispatch what arrived (never blocks). Returns the next timer interval, None when idle."""
        if self.runner is not None:
            for msg in self.runner.poll():
                self._dispatch(msg)
        if self.jobs:
            return POLL_INTERVAL
        self._show_progress(None)
        return None

    def _dispatch(self, msg: dict) -> None:
        job = self.jobs.get(msg.get("id"))
        kind = msg.get("type")
        if job is None:  # answers to cancel requests, worker notes without a job
            if kind in ("log", "error") and msg.get("id") is None:
                print(f"ShapeMove worker: {msg.get('message')}", file=sys.stderr)
            return
        if kind == "progress":
            job.fraction = msg["fraction"]
            self._set_status(f"{job.label}: {100 * job.fraction:.0f}% {msg['message']}".rstrip())
            self._call(job.on_progress, msg)
        elif kind == "log":
            if job.on_log is not None:
                self._call(job.on_log, msg)
            else:
                print(f"[{job.label}] {msg['message']}")
        elif kind == "result":
            del self.jobs[msg["id"]]
            self._set_status(f"{job.label}: {'cancelled' if msg.get('cancelled') else 'done'}")
            self._call(job.on_result, msg)
        elif kind == "error":
            del self.jobs[msg["id"]]
            self._set_status(f"{job.label} failed: {msg['message']}")
            if job.on_error is not None:
                self._call(job.on_error, msg)
            else:
                report_error(f"{job.label} failed: {msg['message']}")
        self._show_progress(min((j.fraction for j in self.jobs.values()), default=None))

    def _call(self, callback, msg) -> None:
        if callback is None:
            return
        try:
            callback(msg)
        except Exception as exc:  # noqa: BLE001  (a callback's bug must not stop the timer)
            traceback.print_exc()
            self._set_status(f"error in a job callback: {type(exc).__name__}: {exc}")

    # -- UI -----------------------------------------------------------------------------------
    def _set_status(self, text: str) -> None:
        self.status = text
        wm = getattr(bpy.context, "window_manager", None)
        if wm is not None and hasattr(wm, "shapemove_status"):
            wm.shapemove_status = text[:500]
        _redraw(wm)

    def _show_progress(self, fraction: float | None) -> None:
        wm = getattr(bpy.context, "window_manager", None)
        if wm is None:
            return
        if hasattr(wm, "shapemove_progress"):
            wm.shapemove_progress = 0.0 if fraction is None else fraction
        if bpy.app.background or not wm.windows:
            return
        if fraction is None:
            if self._progress_shown:
                wm.progress_end()
                self._progress_shown = False
            return
        if not self._progress_shown:
            wm.progress_begin(0.0, 1.0)
            self._progress_shown = True
        wm.progress_update(fraction)


def _redraw(wm) -> None:
    for window in getattr(wm, "windows", []):
        for area in window.screen.areas:
            area.tag_redraw()


def report_error(text: str) -> None:
    """A popup in the UI; stderr when Blender runs without windows."""
    wm = getattr(bpy.context, "window_manager", None)
    if wm is not None and wm.windows and not bpy.app.background:
        wm.popup_menu(lambda menu, _ctx: menu.layout.label(text=text), title="ShapeMove", icon="ERROR")
    else:
        print(f"ShapeMove: {text}", file=sys.stderr)


_MANAGER: list[JobManager] = []


def manager() -> JobManager:
    """The add-on's one JobManager."""
    if not _MANAGER:
        _MANAGER.append(JobManager())
    return _MANAGER[0]


def _tick():
    try:
        return manager().poll()
    except Exception:  # noqa: BLE001  (keep ticking: the next poll may succeed)
        traceback.print_exc()
        return POLL_INTERVAL


class SHAPEMOVE_OT_cancel_jobs(bpy.types.Operator):
    """Cancel the running ShapeMove jobs (training stops after saving a checkpoint)"""

    bl_idname = "shapemove.cancel_jobs"
    bl_label = "Cancel ShapeMove Jobs"

    @classmethod
    def poll(cls, context):
        return manager().busy

    def execute(self, context):
        manager().cancel()
        return {"FINISHED"}


classes = (SHAPEMOVE_OT_cancel_jobs,)


def register() -> None:
    bpy.types.WindowManager.shapemove_status = StringProperty(name="ShapeMove status", default="")
    bpy.types.WindowManager.shapemove_progress = FloatProperty(name="Progress", min=0.0, max=1.0,
                                                              subtype="FACTOR", default=0.0)


def unregister() -> None:
    if bpy.app.timers.is_registered(_tick):
        bpy.app.timers.unregister(_tick)
    if _MANAGER:
        _MANAGER[0].set_runner(None)
        _MANAGER.clear()
    for name in ("shapemove_status", "shapemove_progress"):
        if hasattr(bpy.types.WindowManager, name):
            delattr(bpy.types.WindowManager, name)

