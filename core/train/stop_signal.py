"""Ctrl-C or ``kill`` (SIGINT, SIGTERM) stops a training run at the end of its step, with ``last.pt``
written, instead of losing the steps since the last checkpoint: the training loops' ``cancel``.

    with stop_requested() as stop:          # stop() -> True once a signal came
        train_vae(..., cancel=stop)

A second signal while the step finishes stops at once (Python's default for the signal). The
handlers are put back as they were on leaving; outside the main thread nothing is installed.
"""
from __future__ import annotations

import signal
import sys
import threading
from contextlib import contextmanager

SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextmanager
def stop_requested():
    came: list[int] = []

    def handler(signum, frame):
        if came:   # asked twice: stop now
            signal.signal(signum, signal.SIG_DFL)
            signal.raise_signal(signum)
            return
        came.append(signum)
        print(f"{signal.Signals(signum).name}: stopping after this step, last.pt is written "
              f"(continue with --resume; once more to stop at once)", file=sys.stderr, flush=True)

    if threading.current_thread() is not threading.main_thread():
        yield lambda: False
        return
    before = {s: signal.getsignal(s) for s in SIGNALS}
    for s in SIGNALS:
        signal.signal(s, handler)
    try:
        yield lambda: bool(came)
    finally:
        for s, h in before.items():
            signal.signal(s, h)
