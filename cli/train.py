"""`python -m shapemove train KIND --data DIR --config small|paper|PATH.json --out RUN [--steps N] [--resume|--force]`.

KIND is vae (SA-VAE), t5, tma or head (a new [BETA] head for ``--model DIR``, the T5 frozen). Each kind
lives in ``core/train/train_KIND.py`` and defines
``from_cli(args, cancel) -> dict`` (the final metrics) reading the common arguments below (add a
kind to ``KINDS``); ``cancel()`` turns True on Ctrl-C or ``kill`` (``core/train/stop_signal.py``):
the run stops at the end of its step with ``last.pt`` written. Several processes: ``torchrun --nproc_per_node N -m
shapemove train vae ...`` (DistributedDataParallel; gloo on CPU, nccl on GPU).
"""
from __future__ import annotations

import importlib
import json
import os
from pathlib import Path

from ..core.errors import ShapeMoveError
from ..core.train.run_guard import check_run_folder

KINDS = {"vae": "the shape-aware VAE (stage 1)", "t5": "text -> motion tokens + [BETA] head (stage 2)",
         "tma": "the text-motion retrieval model (TMA)",
         "head": "a new [BETA] head for an exported model, its T5 frozen (reads the shape words)"}


def _module(kind: str):
    try:
        return importlib.import_module(f"...core.train.train_{kind}", __name__)
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.endswith(f"train_{kind}"):
            raise ShapeMoveError(f"`train {kind}` is not available in this build") from exc
        raise


def add_arguments(p):
    sub = p.add_subparsers(dest="kind", metavar="KIND", required=True)
    for kind, help_text in KINDS.items():
        s = sub.add_parser(kind, help=help_text, description=help_text)
        s.add_argument("--data", type=Path, required=True, help="dataset folder from `data build`")
        s.add_argument("--config", default="small", help="tiny | small | paper (core/config_presets.py) or a JSON file (default: small)")
        s.add_argument("--out", type=Path, required=True, help="run folder (checkpoints, log.jsonl)")
        s.add_argument("--steps", type=int, help="override the config's number of steps")
        s.add_argument("--resume", action="store_true", help="continue from RUN/last.pt if it exists")
        s.add_argument("--force", action="store_true",
                       help="train a new model even if RUN already holds one (it is replaced at the end)")
        s.add_argument("--device", choices=["cpu", "cuda"], help="default: cuda when available")
        s.add_argument("--body", help="body model: openbody (default) or an SMPL-family file")
        s.add_argument("--quiet", action="store_true", help="no progress bar")
        if kind == "vae":
            s.add_argument("--init-from", type=Path, default=None,
                           help="fine-tune this trained savae.pt (sets the config's train.init_from; "
                                "train.freeze names the parts kept as they are)")
            s.add_argument("--minutes", type=float, default=None,
                           help="a time budget: the step count is fitted to it once the first steps are timed")
        if kind == "head":
            s.add_argument("--model", type=Path, default=None,
                           help="exported model folder whose T5 stays as it is (default: the shipped model, "
                                "weights/default); RUN/model/ is that folder with the new head")
        if kind == "t5":
            s.add_argument("--vae", type=Path, required=True, help="trained SA-VAE (savae.pt) that tokenizes the motions")
            s.add_argument("--base-model", type=Path, default=None,
                           help="local pretrained T5 folder (e.g. flan-t5-base on disk) instead of a fresh small T5")


def run(args) -> int:
    from ..core.train.stop_signal import stop_requested

    check_run_folder(args.out, args.kind, resume=args.resume, force=args.force)
    with stop_requested() as stop:   # Ctrl-C / kill: last.pt written at the end of the step
        metrics = _module(args.kind).from_cli(args, cancel=stop)
        stopped = stop()
    if stopped:
        print(f"stopped at step {(metrics or {}).get('step', '?')}: {args.out}/last.pt holds the run; "
              f"the same command with --resume continues it")
    if int(os.environ.get("RANK", 0)) == 0 and metrics:
        print(json.dumps(metrics, indent=1))
    return 0
