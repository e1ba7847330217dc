"""Run job ops one at a time in a background thread, with progress and cancel; shared by the worker
process (``server``) and the in-process runner (``client.InProcessRunner``).

``JobRunner(emit, jobs)``: ``handle(request)`` answers the control ops (ping, cancel, shutdown) at
once and queues every other op; the thread runs ``jobs[op](params, progress, cancel) -> dict`` and
calls ``emit(message_dict)`` (from any thread) with protocol responses.
"""
from __future__ import annotations

import atexit
import math
import os
import sys
import threading
import time
import traceback
from collections import deque
from dataclasses import dataclass, field

from ..errors import ShapeMoveError
from . import protocol as P
from .op_support import JobCancelled
from .ops import default_jobs, panel_ops_problem

PROGRESS_INTERVAL = 0.05  # s: progress calls closer together than this are dropped (except 100%)


@dataclass
class _Job:
    id: object
    op: str
    params: dict
    cancel_event: threading.Event = field(default_factory=threading.Event)
    last_progress: float = -1.0


class JobRunner:
    def __init__(self, emit, jobs: dict | None = None):
        self.emit = emit
        self.jobs = default_jobs() if jobs is None else jobs
        self._queue: deque[_Job] = deque()
        self._current: _Job | None = None
        self._cv = threading.Condition()
        self._closing = False
        self._thread = threading.Thread(target=self._loop, name="shapemove-job", daemon=True)
        self._thread.start()
        # bpy 4.2-4.5 crash or hang at interpreter exit while a thread still runs: stop it first
        atexit.register(self.close, 1.0)

    # -- requests -----------------------------------------------------------------------------
    @property
    def current_id(self):
        job = self._current
        return job.id if job is not None else None

    def handle(self, req: P.Request) -> bool:
        """Answer or queue one request. Returns False after "shutdown" (stop reading)."""
        if req.op == "ping":
            with self._cv:
                busy, queued = self.current_id, [j.id for j in self._queue]
            self.emit(P.result(req.id, {"pong": True, "pid": os.getpid(), "python": sys.version.split()[0],
                                        "protocol": P.PROTOCOL_VERSION, "ops": sorted(self.jobs),
                                        "running": busy, "queued": queued}))
        elif req.op == "cancel":
            self.emit(P.result(req.id, self.cancel(req.params.get("job"))))
        elif req.op == "shutdown":
            self.close(wait=float(req.params.get("timeout", 10.0)))
            self.emit(P.result(req.id, {"shutdown": True}))
            return False
        elif req.op not in self.jobs:
            note = f" ({panel_ops_problem()})" if panel_ops_problem() else ""
            self.emit(P.error(req.id, f"unknown op {req.op!r}; known ops: "
                                      f"{', '.join(sorted([*P.CONTROL_OPS, *self.jobs]))}{note}"))
        else:
            with self._cv:
                if self._closing:
                    self.emit(P.error(req.id, "the worker is shutting down"))
                elif req.id == self.current_id or any(j.id == req.id for j in self._queue):
                    self.emit(P.error(req.id, f"a job with id {req.id!r} is already running or queued"))
                else:
                    self._queue.append(_Job(req.id, req.op, req.params))
                    self._cv.notify()
        return True

    def cancel(self, job_id) -> dict:
        """Cancel a queued job (it ends at once) or ask the running one to stop."""
        with self._cv:
            if self._current is not None and self._current.id == job_id:
                self._current.cancel_event.set()
                return {"job": job_id, "state": "running"}
            for job in list(self._queue):
                if job.id == job_id:
                    self._queue.remove(job)
                    self.emit(P.result(job.id, {}, cancelled=True))
                    return {"job": job_id, "state": "queued"}
        return {"job": job_id, "state": "unknown"}

    def close(self, wait: float = 10.0) -> None:
        """Cancel everything, stop the thread (waiting up to ``wait`` s for the running job)."""
        with self._cv:
            self._closing = True
            ids = [j.id for j in self._queue]
            current = self._current
        for jid in ids:
            self.cancel(jid)
        if current is not None:
            current.cancel_event.set()
        with self._cv:
            self._cv.notify_all()
        self._thread.join(wait)

    # -- the job thread -------------------------------------------------------------------------
    def _loop(self) -> None:
        while True:
            with self._cv:
                while not self._queue and not self._closing:
                    self._cv.wait()
                if self._closing and not self._queue:
                    return
                self._current = job = self._queue.popleft()
            try:
                self._run(job)
            finally:
                with self._cv:
                    self._current = None

    def _run(self, job: _Job) -> None:
        def progress(fraction, message="") -> None:
            f = float(fraction)
            f = 0.0 if not math.isfinite(f) else min(max(f, 0.0), 1.0)
            now = time.monotonic()
            if f < 1.0 and now - job.last_progress < PROGRESS_INTERVAL:
                return
            job.last_progress = now
            self.emit(P.progress(job.id, f, str(message)))

        cancel = job.cancel_event.is_set
        try:
            data = self.jobs[job.op](job.params, progress, cancel)
            msg = P.result(job.id, {} if data is None else data, cancelled=cancel())
            P.encode_response(msg)  # refuse a result that cannot travel, as an error of this job
        except JobCancelled:
            msg = P.result(job.id, {}, cancelled=True)
        except ShapeMoveError as exc:
            msg = P.error(job.id, str(exc), "ShapeMoveError")
        except ModuleNotFoundError as exc:  # the chosen Python lacks a requirement
            traceback.print_exc(file=sys.stderr)
            msg = P.error(job.id, f"op {job.op!r} needs the Python package {exc.name!r}, which is not installed in "
                                  f"{sys.executable}", "ModuleNotFoundError")
        except BaseException as exc:  # noqa: BLE001  (a job's bug, even sys.exit, must not kill the worker)
            traceback.print_exc(file=sys.stderr)
            msg = P.error(job.id, f"{type(exc).__name__}: {exc}", type(exc).__name__)
        self.emit(msg)
