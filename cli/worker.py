"""`python -m shapemove worker`: serve jobs over stdin/stdout (JSON lines) for the Blender extension.

The protocol is described in core/worker/protocol.py; the ops in core/worker/ops.py.
``--list`` prints the ops and exits (without serving).
"""
from __future__ import annotations

from ..core.worker.ops import default_jobs
from ..core.worker.protocol import CONTROL_OPS
from ..core.worker.server import main


def add_arguments(p):
    p.add_argument("--list", action="store_true", help="print the available ops and exit")


def run(args) -> int:
    if args.list:
        for name in [*CONTROL_OPS, *sorted(default_jobs())]:
            print(name)
        return 0

    return main()
