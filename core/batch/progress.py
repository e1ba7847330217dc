"""A batch's progress for a person and for a log: items done / failed / left, the rate and the time
left. A bar (tqdm) on a terminal; elsewhere a plain line every ``interval`` seconds and at the end."""
from __future__ import annotations

import sys
import time


def _duration(s: float) -> str:
    s = int(round(s))
    return f"{s // 3600}h{s % 3600 // 60:02d}m" if s >= 3600 else f"{s // 60}m{s % 60:02d}s" if s >= 60 else f"{s}s"


class BatchProgress:
    def __init__(self, total: int, already: int = 0, label: str = "batch", stream=None, interval: float = 10.0,
                 bar: bool | None = None):
        self.total, self.already, self.label = total, already, label
        self.stream = stream or sys.stderr
        self.interval = interval
        self.done = self.failed = 0
        self.t0 = self._last = time.monotonic()
        self._printed = None
        tty = bar if bar is not None else getattr(self.stream, "isatty", lambda: False)()
        self.bar = None
        if tty:
            from tqdm import tqdm

            self.bar = tqdm(total=total, initial=already, desc=label, unit="item", file=self.stream)

    @property
    def left(self) -> int:
        return self.total - self.already - self.done - self.failed

    @property
    def rate(self) -> float:
        elapsed = time.monotonic() - self.t0
        return (self.done + self.failed) / elapsed if elapsed > 0 else 0.0

    def line(self) -> str:
        rate = self.rate
        eta = f", about {_duration(self.left / rate)} left" if rate > 0 and self.left else ""
        return (f"{self.label}: {self.already + self.done} of {self.total} done ({self.already} before this run), "
                f"{self.failed} failed, {self.left} left, {rate:.2f} items/s{eta}")

    def update(self, ok: bool) -> None:
        if ok:
            self.done += 1
        else:
            self.failed += 1
        if self.bar is not None:
            self.bar.update(1)
            self.bar.set_postfix(failed=self.failed, refresh=False)
        elif time.monotonic() - self._last >= self.interval:
            self._last = time.monotonic()
            self._print()

    def write(self, text: str) -> None:
        if self.bar is not None:
            self.bar.write(text, file=self.stream)
        else:
            print(text, file=self.stream, flush=True)

    def _print(self) -> None:
        text = self.line()
        if text != self._printed:
            print(text, file=self.stream, flush=True)
            self._printed = text

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        self._print()
