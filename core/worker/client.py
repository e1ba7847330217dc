"""Run jobs without blocking the caller: in a worker process (``WorkerClient``) or in a thread of
this process (``InProcessRunner``). Pure Python (no bpy): the Blender side polls them from a timer.

Both have the same interface:
    start(); submit(op, params) -> job id; poll() -> [message dicts] (never blocks);
    cancel(job_id); alive() -> bool; stop(); restart(); pending -> {job id: op};
    call(op, params, timeout) -> result dict (blocking; for scripts and tests, not the UI thread).
Messages are the protocol responses (core/worker/protocol.py). A job ends with exactly one
"result" or "error" message. When the worker process dies, every job it had gets an error
"worker process died (exit code N)"; the next ``submit`` starts a fresh process.
"""
from __future__ import annotations

import importlib.util
import os
import queue
import re
import subprocess
import sys
import threading
import time
from collections import deque
from pathlib import Path

from . import protocol as P
from ..errors import ShapeMoveError
from .runner import JobRunner

PACKAGE_ROOT = Path(__file__).resolve().parents[2]  # the folder holding shapemove's __init__.py
# Imports this package's folder as `shapemove` (whatever the folder is called, e.g. inside
# Blender's extensions) in the chosen Python and runs its worker command.
LAUNCHER = (
    "import sys, importlib.util as u\n"
    "root = sys.argv[1]\n"
    "spec = u.spec_from_file_location('shapemove', root + '/__init__.py', submodule_search_locations=[root])\n"
    "mod = u.module_from_spec(spec); sys.modules['shapemove'] = mod; spec.loader.exec_module(mod)\n"
    "from shapemove.cli import main\n"
    "raise SystemExit(main(['worker']))\n"
)
DEATH_GRACE = 2.0  # s to wait for the last output of a process that has exited


def resolve_python(path) -> Path:
    """A Python executable, or a virtual environment / conda folder holding one -> the executable."""
    p = Path(str(path)).expanduser()
    if p.is_dir():
        for rel in ("bin/python3", "bin/python", "Scripts/python.exe", "python.exe", "python3", "python"):
            if (p / rel).is_file():
                return p / rel
        raise ShapeMoveError(f"no Python executable in the environment folder {p} (looked in bin/ and Scripts/)")
    if not p.is_file():
        raise ShapeMoveError(f"Python environment not found: {p} (give a python executable or its environment folder)")
    return p


_TORCH: list = []


def torch_importable() -> bool:
    """True when torch imports in this Python (checked once; the import itself takes a few seconds)."""
    if not _TORCH:
        ok = importlib.util.find_spec("torch") is not None
        if ok:
            try:
                import torch  # noqa: F401
            except Exception:  # noqa: BLE001  (a broken install counts as absent)
                ok = False
        _TORCH.append(ok)
    return _TORCH[0]


class _Jobs:
    """What both runners share: job ids, the pending table, draining the message queue."""

    def _init_jobs(self):
        self._messages: queue.Queue = queue.Queue()
        self.pending: dict = {}  # job id -> op, until its result/error was returned by poll()
        self._finished: set = set()  # jobs that ended, and our own cancel/shutdown requests
        self._count = 0

    def _new_id(self, prefix: str = "j") -> str:
        self._count += 1
        return f"{prefix}{self._count}"

    def _take(self, msg: dict, out: list) -> None:
        jid = msg.get("id")
        if jid in self._finished:
            return  # a job ends once (drop a late answer after its "died"/"stopped" error); acks of ours
        if msg.get("type") in ("result", "error") and jid in self.pending:
            del self.pending[jid]
            self._finished.add(jid)
        out.append(msg)

    def _fail_pending(self, message: str, error_type: str, ids=None) -> None:
        for jid in list(self.pending if ids is None else ids):
            self._messages.put(P.error(jid, message, error_type))

    def call(self, op: str, params: dict | None = None, timeout: float = 120.0, on_message=None) -> dict:
        """Submit and wait for the end (blocking): the result dict, or ShapeMoveError with the job's
        error message (also on timeout). ``on_message(msg)`` sees every message of the job."""
        jid = self.submit(op, params)
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            for msg in self.poll():
                if msg.get("id") != jid:
                    continue
                if on_message is not None:
                    on_message(msg)
                if msg["type"] == "error":
                    raise ShapeMoveError(msg["message"])
                if msg["type"] == "result":
                    return msg["result"]
            time.sleep(0.01)
        self.cancel(jid)
        raise ShapeMoveError(f"op {op!r} did not finish within {timeout:g} s (cancelled)")


class WorkerClient(_Jobs):
    """Jobs in a child process ``python_exe`` running the worker (``-m shapemove worker``-style).

    env: extra environment variables for the child; cwd: its working folder; command: the full
    command line to run instead of the default launcher of this package."""

    def __init__(self, python_exe, env: dict | None = None, cwd=None, command: list | None = None,
                 stderr_lines: int = 200):
        self.python_exe = str(python_exe)
        self.env, self.cwd = env, cwd
        self.command = list(command) if command else [self.python_exe, "-u", "-c", LAUNCHER, str(PACKAGE_ROOT)]
        self.proc: subprocess.Popen | None = None
        self.stderr_tail: deque[str] = deque(maxlen=stderr_lines)
        self.exit_code: int | None = None
        self.starts = 0
        self.bad_lines = 0  # stdout lines that were not protocol messages (should stay 0)
        self._gen = 0
        self._owner: dict = {}  # job id -> process generation that has it
        self._exited_at: float | None = None
        self._reader: threading.Thread | None = None
        self._write_lock = threading.Lock()
        self._init_jobs()

    # -- process ------------------------------------------------------------------------------
    def start(self) -> None:
        """Start the worker process (no-op when it runs)."""
        if self.alive():
            return
        if self.proc is not None:
            self._reap("worker process died", "WorkerDied")
        env = {k: v for k, v in os.environ.items() if k != "PYTHONHOME"}  # Blender's would break another Python
        env.update(self.env or {})
        env["PYTHONUNBUFFERED"] = "1"
        try:
            proc = subprocess.Popen(self.command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, env=env, cwd=self.cwd)
        except OSError as exc:
            raise ShapeMoveError(f"cannot start the ShapeMove worker with {self.command[0]}: {exc}") from None
        self._gen += 1
        self.proc, self.exit_code, self._exited_at = proc, None, None
        self.starts += 1
        self.stderr_tail.clear()
        gen = self._gen
        self._reader = threading.Thread(target=self._read_stdout, args=(proc, gen), daemon=True,
                                        name="shapemove-worker-out")
        self._reader.start()
        threading.Thread(target=self._read_stderr, args=(proc,), daemon=True, name="shapemove-worker-err").start()

    def alive(self) -> bool:
        return self.proc is not None and self.proc.poll() is None

    @property
    def pid(self) -> int | None:
        return self.proc.pid if self.proc is not None else None

    def stop(self, timeout: float = 5.0) -> None:
        """Ask the worker to shut down (cancels its jobs), kill it after ``timeout`` s."""
        if self.proc is None:
            return
        if self.alive():
            self._send(self._new_id("s"), "shutdown", {"timeout": max(timeout - 1.0, 0.5)})
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._reap("worker stopped", "WorkerStopped")

    def restart(self) -> None:
        self.stop(timeout=2.0)
        self.start()

    def _reap(self, why: str, error_type: str) -> None:
        """The current process is gone: close its pipes, fail its jobs that have no answer yet."""
        proc, gen = self.proc, self._gen
        if proc.poll() is None:
            proc.kill()
        self.exit_code = proc.wait()
        self._reader.join(DEATH_GRACE)  # its last answers are queued before the errors below
        for pipe in (proc.stdin, proc.stdout, proc.stderr):
            try:
                pipe.close()
            except OSError:
                pass
        ids = [jid for jid in self.pending if self._owner.get(jid) == gen]
        for jid in ids:
            self._owner.pop(jid, None)
        tail = " | ".join(list(self.stderr_tail)[-3:])
        self._fail_pending(f"{why} (exit code {self.exit_code})" + (f" - last output: {tail}" if tail else ""),
                           error_type, ids)
        self.proc = None

    # -- jobs ---------------------------------------------------------------------------------
    def submit(self, op: str, params: dict | None = None) -> str:
        """Queue a job in the worker (starting it if needed) -> its id."""
        if not self.alive():
            self.start()
        jid = self._new_id()
        line = P.encode_request(jid, op, params)  # bad params types fail here, in the caller
        self.pending[jid] = op
        self._owner[jid] = self._gen
        self._write(line)
        return jid

    def cancel(self, job_id) -> bool:
        """Ask the worker to cancel a job; its end still arrives through poll()."""
        if job_id not in self.pending or not self.alive():
            return False
        self._send(self._new_id("c"), "cancel", {"job": job_id})
        return True

    def poll(self) -> list[dict]:
        """Every message received since the last call (non-blocking); detects a dead worker."""
        out: list[dict] = []
        while True:
            try:
                item = self._messages.get_nowait()
            except queue.Empty:
                break
            if isinstance(item, tuple):  # ("eof", generation): that process closed its stdout
                if item[1] == self._gen and self.proc is not None:
                    self._reap("worker process died", "WorkerDied")
                continue
            self._take(item, out)
        if self.proc is not None and self.proc.poll() is not None:  # exited, stdout maybe held open
            self._exited_at = self._exited_at or time.monotonic()
            if time.monotonic() - self._exited_at > DEATH_GRACE:
                self._reap("worker process died", "WorkerDied")
                out += self.poll()
        return out

    # -- pipes --------------------------------------------------------------------------------
    def _send(self, rid, op: str, params: dict) -> None:
        self._finished.add(rid)  # its answer is not for the caller
        self._write(P.encode_request(rid, op, params))

    def _write(self, line: str) -> None:
        proc = self.proc
        try:
            with self._write_lock:
                proc.stdin.write((line + "\n").encode("utf-8"))
                proc.stdin.flush()
        except (OSError, ValueError, AttributeError):
            pass  # the process is gone: poll() reports it to the pending jobs

    def _read_stdout(self, proc, gen: int) -> None:
        try:
            for raw in iter(proc.stdout.readline, b""):
                try:
                    msg = P.decode_response(raw)
                except P.ProtocolError:
                    self.bad_lines += 1
                    text = raw.decode("utf-8", "replace").rstrip()
                    msg = P.log(None, f"worker wrote a non-protocol line: {text[:200]}")
                self._messages.put(msg)
        except (OSError, ValueError):
            pass  # the pipe was closed under us (stop/restart)
        self._messages.put(("eof", gen))

    def _read_stderr(self, proc) -> None:
        partial = ""
        try:
            for chunk in iter(lambda: proc.stderr.read1(65536), b""):
                *lines, partial = re.split(r"[\r\n]", partial + chunk.decode("utf-8", "replace"))
                self.stderr_tail.extend(line for line in lines if line.strip())
        except (OSError, ValueError):
            pass
        if partial.strip():
            self.stderr_tail.append(partial)


class InProcessRunner(_Jobs):
    """The same jobs in a thread of this process (when torch imports here, e.g. headless Blender).
    Messages go through the protocol's encoder and decoder, so they are exactly the worker's."""

    def __init__(self, jobs: dict | None = None):
        self.jobs = jobs
        self._runner = None
        self._init_jobs()

    def start(self) -> None:
        if not self.alive():
            self._runner = JobRunner(self._emit, self.jobs)

    def _emit(self, msg: dict) -> None:
        try:
            msg = P.decode_response(P.encode_response(msg))
        except P.ProtocolError as exc:
            msg = P.error(msg.get("id"), str(exc), "ProtocolError")
        self._messages.put(msg)

    def alive(self) -> bool:
        return self._runner is not None and self._runner._thread.is_alive()

    def submit(self, op: str, params: dict | None = None) -> str:
        self.start()
        jid = self._new_id()
        P.encode_request(jid, op, params)  # same checks as for the worker process
        self.pending[jid] = op
        self._runner.handle(P.Request(jid, op, dict(params or {})))
        return jid

    def cancel(self, job_id) -> bool:
        if job_id not in self.pending or self._runner is None:
            return False
        self._runner.cancel(job_id)
        return True

    def poll(self) -> list[dict]:
        out: list[dict] = []
        while True:
            try:
                self._take(self._messages.get_nowait(), out)
            except queue.Empty:
                return out

    def stop(self, timeout: float = 5.0) -> None:
        """Cancel the jobs and wait up to ``timeout`` s for the running one to return."""
        if self._runner is None:
            return
        self._runner.close(wait=timeout)
        self._runner = None
        self._fail_pending("runner stopped", "WorkerStopped")  # jobs that answered keep their answer

    def restart(self) -> None:
        self.stop()
        self.start()


def default_runner(python_exe=None, env: dict | None = None):
    """WorkerClient when a Python is given (path to it or its environment), else InProcessRunner
    when torch imports here; otherwise ShapeMoveError saying what to set up."""
    if python_exe:
        return WorkerClient(resolve_python(python_exe), env=env)
    if torch_importable():
        return InProcessRunner()
    raise ShapeMoveError("PyTorch is not installed in Blender's Python: set 'Python environment' in the "
                         "ShapeMove add-on preferences to a Python (or venv) where torch and ShapeMove's "
                         "requirements are installed")
