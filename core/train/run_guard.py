"""Never lose a training run by accident: ``train KIND --out RUN`` into a folder that already holds
a finished model or an interrupted run is refused unless ``--resume`` (continue it) or ``--force``
(train a new one over it) is given."""
from __future__ import annotations

from pathlib import Path

from ..errors import ShapeMoveError

FINISHED = {"vae": "savae.pt", "t5": "t5/shapemove.json", "tma": "tma.pt", "head": "model/manifest.json"}


def check_run_folder(out, kind: str, resume: bool = False, force: bool = False) -> None:
    """Raise ShapeMoveError when training ``kind`` into ``out`` would replace earlier work."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ShapeMoveError(f"--out {out} is a file, not a folder")
    if resume or force or not out.is_dir():
        return
    done = out / FINISHED.get(kind, "")
    if kind in FINISHED and done.is_file():
        raise ShapeMoveError(f"{out} already holds a finished {kind} model ({done.relative_to(out)}): pass --resume "
                             "to continue or extend that run, --force to train a new model over it, or another --out")
    if (out / "last.pt").is_file():
        raise ShapeMoveError(f"{out} holds an interrupted run (last.pt): pass --resume to continue it, --force to "
                             "start over, or another --out")
