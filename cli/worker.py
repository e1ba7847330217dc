"""`python -m shapemove worker`: serve jobs over stdin/stdout (JSON lines) for the Blender extension.

The protocol is described in core/worker/protocol.py; the ops in core/worker/ops.py.
``--list`` prints the ops and exits (without serving). The worker process also has the ``cli`` op
(cli/job_op.py: run a command in the worker), added here because core never imports the CLI.
"""
from __future__ import annotations

from ..core.worker.ops import default_jobs, register
from ..core.worker.protocol import CONTROL_OPS
from ..core.worker.server import main
from .job_op import cli


def add_arguments(p):
    p.add_argument("--list", action="store_true", help="print the available ops and exit")


def run(args) -> int:
    register("cli", cli)
    if args.list:
        for name in [*CONTROL_OPS, *sorted(default_jobs())]:
            print(name)
        return 0

    return main()
