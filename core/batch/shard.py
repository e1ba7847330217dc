"""``--shard I/N``: every N-th item from item I (0 <= I < N), so N machines split one batch without
talking to each other; the shards' manifests are joined by ``batch merge`` (``merge.py``)."""
from __future__ import annotations

import re
from typing import NamedTuple

from ..errors import ShapeMoveError

MAX_SHARDS = 1_000_000


class Shard(NamedTuple):
    index: int
    count: int

    def holds(self, item: int) -> bool:
        return item % self.count == self.index

    @property
    def label(self) -> str:
        return f"{self.index}/{self.count}"


ALL = Shard(0, 1)


def parse_shard(text) -> Shard:
    """'I/N' -> Shard(I, N); None -> the whole batch."""
    if text is None:
        return ALL
    m = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", str(text))
    if not m:
        raise ShapeMoveError(f"--shard takes I/N (for example 0/4: items 0, 4, 8, ...), got {text!r}")
    i, n = int(m.group(1)), int(m.group(2))
    if not 1 <= n <= MAX_SHARDS or not 0 <= i < n:
        raise ShapeMoveError(f"--shard {text}: N must be 1 to {MAX_SHARDS:,} and I from 0 to N-1")
    return Shard(i, n)
