"""`python -m shapemove worker`: serve jobs over stdin/stdout, one JSON line per message.

The main thread reads requests; a ``JobRunner`` thread runs the jobs one at a time. stdout carries
protocol lines only: at start the real stdout is kept for the protocol, file descriptor 1 is
pointed at stderr (so C-level output lands there) and ``sys.stdout`` becomes a stream that copies
printed lines to stderr and sends them as "log" messages of the running job. End of input (the
parent process died or closed the pipe) works like "shutdown".
"""
from __future__ import annotations

import io
import os
import sys
import threading

from . import protocol as P
from .ops import JOBS  # noqa: F401  (the registry: JOBS[name] = func(params, progress, cancel) -> dict)
from .runner import JobRunner


class _Writer:
    """Thread-safe protocol output: one line per message, flushed."""

    def __init__(self, stream):
        self.stream = stream
        self.lock = threading.Lock()

    def __call__(self, msg: dict) -> None:
        try:
            line = P.encode_response(msg)
        except P.ProtocolError as exc:  # a bug of ours: say so instead of dying
            rid = msg.get("id") if isinstance(msg, dict) else None
            line = P.encode_response(P.error(rid if isinstance(rid, (str, int)) else None, str(exc), "ProtocolError"))
        with self.lock:
            try:
                self.stream.write(line + "\n")
                self.stream.flush()
            except (BrokenPipeError, ValueError, OSError):
                pass  # the parent is gone; the read loop ends at end of input


class _PrintsToLog(io.TextIOBase):
    """sys.stdout while serving: complete lines go to stderr and out as log messages."""

    def __init__(self, emit, current_id, stderr):
        self.emit, self.current_id, self.stderr = emit, current_id, stderr
        self.buf = ""

    def writable(self) -> bool:
        return True

    def write(self, s: str) -> int:
        self.stderr.write(s)
        self.buf += s
        *lines, self.buf = self.buf.replace("\r", "\n").split("\n")
        for line in lines:
            if line.strip():
                self.emit(P.log(self.current_id(), line))
        return len(s)

    def flush(self) -> None:
        self.stderr.flush()


def _bounded_lines(stream, limit: int):
    """Lines of ``stream``, reading at most ``limit`` + 1 characters at a time: a longer line is
    read through in chunks and yielded as None, so a 300 MB line never sits in memory."""
    while True:
        line = stream.readline(limit + 1)
        if not line:
            return
        if len(line) <= limit or line.endswith("\n"):
            yield line
            continue
        while line and not line.endswith("\n"):  # discard the rest of the line
            line = stream.readline(1 << 20)
        yield None


def serve(stdin, stdout, jobs: dict | None = None, capture_prints: bool = False) -> int:
    """Read requests from ``stdin`` (text lines) and write responses to ``stdout`` until "shutdown"
    or end of input. ``capture_prints``: sys.stdout becomes stderr + log messages meanwhile."""
    emit = _Writer(stdout)
    runner = JobRunner(emit, jobs)
    old_stdout = sys.stdout
    if capture_prints:
        sys.stdout = _PrintsToLog(emit, lambda: runner.current_id, sys.stderr)
    try:
        for line in _bounded_lines(stdin, P.MAX_LINE):
            if line is None:  # longer than MAX_LINE: skipped without being held in memory
                emit(P.error(None, f"request line is too long (more than {P.MAX_LINE} characters); it was skipped",
                             "ProtocolError"))
                continue
            if not line.strip():
                continue
            try:
                req = P.decode_request(line)
            except P.ProtocolError as exc:
                emit(P.error(exc.request_id, str(exc), "ProtocolError"))
                continue
            if not runner.handle(req):
                break
    except KeyboardInterrupt:
        pass
    finally:
        runner.close()
        sys.stdout = old_stdout
    return 0


def main(jobs: dict | None = None) -> int:
    """Entry point of the `worker` command: keep fd 1 for the protocol only, then serve."""
    sys.stdout.flush()
    proto = os.fdopen(os.dup(1), "w", encoding="utf-8", buffering=1)
    os.dup2(2, 1)  # anything written to file descriptor 1 now lands on stderr
    stdin = io.TextIOWrapper(sys.stdin.buffer, encoding="utf-8", errors="replace", newline="\n")
    return serve(stdin, proto, jobs, capture_prints=True)
