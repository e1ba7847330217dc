"""What every training loop does at a logging step: append the metrics to ``log.jsonl`` in the
run folder and tell the caller's progress callback (the Blender UI, the worker)."""
from __future__ import annotations

import json
from pathlib import Path


def record(out: Path, metrics: dict, progress, step: int, total: int, message: str) -> None:
    with open(Path(out) / "log.jsonl", "a") as f:
        f.write(json.dumps(metrics) + "\n")
    if progress is not None:
        progress(step / total, f"step {step}/{total} {message}")
