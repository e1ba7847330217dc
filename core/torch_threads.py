"""Run torch on one thread for a block of small tensor work.

The tensors of IK (frames x 24 x 4 x 4) and of generation (reading a prompt, writing ~50 tokens) are
small: intra-op threads only add synchronisation, and on a busy 2-core machine waiting for a second
core made the T5 60x slower (6.8 s instead of 0.09 s for 50 tokens)."""
from __future__ import annotations

from contextlib import contextmanager

import torch


@contextmanager
def one_torch_thread():
    """``with one_torch_thread(): ...``: torch's intra-op thread count is 1 inside, restored after."""
    n = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(n)
