"""`python -m shapemove bench [all|ik|keys|sliders|generate|train|long_take|timeline|animation|seams|batch|plant_leaps|gait_pace|distances] [--json OUT]`.

Each benchmark lives in ``bench/<name>.py`` with ``run(quick: bool) -> dict`` and prints its own
baseline (measured in the same run) and the ratio. ``all`` runs them in order and merges the dicts.
"""
from __future__ import annotations

import importlib
from pathlib import Path

from ..core.atomic import atomic_write_json

BENCHES = ["ik", "keys", "sliders", "generate", "train", "long_take", "timeline", "animation", "seams", "batch", "plant_leaps", "gait_pace", "distances"]


def add_arguments(p):
    p.add_argument("target", nargs="?", default="all", choices=["all", *BENCHES])
    p.add_argument("--json", type=Path, help="write the results as JSON here")
    p.add_argument("--quick", action="store_true", help="smaller sizes (smoke run)")


def run(args) -> int:
    targets = BENCHES if args.target == "all" else [args.target]
    results: dict = {}
    for name in targets:
        try:
            mod = importlib.import_module(f"...bench.{name}", __name__)
        except ModuleNotFoundError as exc:
            if exc.name and exc.name.endswith(f"bench.{name}"):
                print(f"[bench {name}] not available in this build, skipped")
                continue
            raise
        print(f"== bench {name}")
        results.update(mod.run(quick=args.quick))
    if args.json:
        atomic_write_json(args.json, results)
        print(f"wrote {args.json}")
    return 0
