"""What every training loop does at a logging step: average the train metrics over the processes,
time the steps since the last logging step, run validation when due, show the numbers on the
progress bar, append the metrics to ``log.jsonl`` in the run folder and tell the caller's progress
callback (the Blender UI, the worker). One definition (:class:`StepLog`) for the SA-VAE, T5 and TMA
loops.

A resumed run restarts from its last checkpoint, which may be older than the last logged step: when
the log's last line is at or after the step being recorded, the lines at or after that step (and
unreadable lines from a crash mid-write) are dropped first, so every step appears once and in
order in ``log.jsonl``."""
from __future__ import annotations

import json
import time
from pathlib import Path

from tqdm import tqdm

from ..atomic import atomic_write_text
from . import distributed


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


class StepLog:
    """The progress bar and the logging step of one training loop, from step ``step`` of ``total``.

    ``bar`` is the tqdm bar (shown on rank 0 when ``verbose``); ``metrics`` holds the last logged
    metrics (``{"step": step}`` before the first logging step)."""

    def __init__(self, out, total: int, step: int, dist, progress, desc: str, verbose: bool = True):
        self.out, self.total, self.dist, self.progress = Path(out), int(total), dist, progress
        self.bar = tqdm(total=total, initial=step, desc=desc, unit="step", disable=not (dist.is_main and verbose))
        self.metrics: dict = {"step": step}
        self._t0, self._s0 = time.time(), step

    def log(self, step: int, lr: float, train: dict, show: dict, validate=None, digits: int = 3) -> dict:
        """Record logging step ``step``: ``train`` (floats, averaged over the processes), the learning
        rate and the seconds per step since the last logging step; on rank 0 ``validate()`` (when
        given; an empty result is left out) goes under ``"val"``. ``show`` maps a bar label to
        (section, key) of the metrics, e.g. ``{"loss": ("train", "total")}``, printed with
        ``digits`` decimals; the first shown value is also the progress message. Returns the metrics."""
        train = distributed.mean_over_ranks(train, self.dist)
        metrics = {"step": step, "lr": lr, "train": train,
                   "sec_per_step": (time.time() - self._t0) / max(1, step - self._s0)}
        if validate is not None and self.dist.is_main:
            val = validate()
            if val:
                metrics["val"] = val
        self._t0, self._s0 = time.time(), step
        if self.dist.is_main:
            shown = {label: f"{metrics[section][key]:.{digits}f}" for label, (section, key) in show.items()
                     if key in metrics.get(section, {})}
            self.bar.set_postfix(**shown)
            label, value = next(iter(shown.items()))
            record(self.out, metrics, self.progress, step, self.total, f"{label} {value}")
        self.metrics = metrics
        return metrics
