"""The worker's ``cli`` op: run a `python -m shapemove` command inside the worker process.

It lives with the commands (not in core/worker/ops.py) so that core never imports the CLI: the
`worker` command adds it to the worker's ops when it starts (cli/worker.py)."""
from __future__ import annotations

import io
import sys
from collections import deque
from contextlib import redirect_stderr

from ..core.errors import ShapeMoveError
from ..core.worker.op_support import str_list
from . import COMMANDS, main


class _Tail(io.TextIOBase):
    """Forwards writes to ``target`` and keeps the last lines (for the error message)."""

    def __init__(self, target, lines: int = 20):
        self.target, self.lines = target, deque(maxlen=lines)

    def write(self, s: str) -> int:
        self.target.write(s)
        self.lines.extend(line for line in s.replace("\r", "\n").split("\n") if line.strip())
        return len(s)

    def flush(self) -> None:
        self.target.flush()


def cli(params, progress, cancel) -> dict:
    """params {"argv": ["data", "build", ...]}: run a `python -m shapemove` command in this process.
    Its printed output arrives as log messages; a failure -> error with its last stderr lines.
    Commands have no cancel hook: a cancelled cli job still runs to its end."""
    argv = str_list(params, "cli", "argv")
    if not argv or argv[0] not in COMMANDS or argv[0] == "worker":
        known = ", ".join(c for c in COMMANDS if c != "worker")
        raise ShapeMoveError(f"op 'cli': argv must start with a command ({known}), got {argv[:1]}")
    tail = _Tail(sys.stderr)
    with redirect_stderr(tail):
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse errors
            code = exc.code if isinstance(exc.code, int) else 2
    if code:
        why = "; ".join(list(tail.lines)[-3:]) or "no message"
        raise ShapeMoveError(f"`shapemove {' '.join(argv)}` failed (exit code {code}): {why}")
    return {"exit_code": 0}
