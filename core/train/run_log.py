"""What every training loop does at a logging step: append the metrics to ``log.jsonl`` in the
run folder and tell the caller's progress callback (the Blender UI, the worker).

A resumed run restarts from its last checkpoint, which may be older than the last logged step: when
the log's last line is at or after the step being recorded, the lines at or after that step (and
unreadable lines from a crash mid-write) are dropped first, so every step appears once and in
order in ``log.jsonl``."""
from __future__ import annotations

import json
from pathlib import Path

from ..atomic import atomic_write_text



def _last_step(log: Path):
    """The step of the log's last line (None if unreadable), reading only its tail."""
    try:
        with open(log, "rb") as fh:
            fh.seek(0, 2)
            size = fh.tell()
            fh.seek(max(0, size - 65536))
            tail = fh.read().decode("utf-8", errors="replace").rstrip("\n").rsplit("\n", 1)[-1]
        return json.loads(tail).get("step")
    except (OSError, ValueError, AttributeError):
        return None


def _trim(log: Path, step: int) -> None:
    if not log.is_file():
        return
    keep, dropped = [], 0
    with open(log, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            try:
                s = json.loads(line).get("step")
            except (ValueError, AttributeError):
                s = None
            if isinstance(s, (int, float)) and s < step:
                keep.append(line if line.endswith("\n") else line + "\n")
            else:
                dropped += 1
    if dropped:
        atomic_write_text(log, "".join(keep))


def record(out: Path, metrics: dict, progress, step: int, total: int, message: str) -> None:
    log = Path(out) / "log.jsonl"
    now = metrics.get("step", step)
    if log.is_file() and log.stat().st_size:
        last = _last_step(log)
        if not isinstance(last, (int, float)) or last >= now:
            _trim(log, now)
    with open(log, "a") as f:
        f.write(json.dumps(metrics) + "\n")
    if progress is not None:
        progress(step / total, f"step {step}/{total} {message}")
