"""Check a generation request's sampling numbers (from the command line, the worker or the UI)
before any model runs: NaN/inf temperatures, negative top-k or out-of-range seeds are a sentence,
not a traceback from deep inside torch."""
from __future__ import annotations

import math

from ..errors import ShapeMoveError

MAX_TEMPERATURE = 100.0
MAX_SEED = 2**63 - 1
DEFAULT_CANDIDATES = 8   # best-of-N token samples (generation/rerank.py)
MAX_CANDIDATES = 64
DEFAULT_GUIDANCE = 2.0    # classifier-free guidance of models trained with null_share (constrained_decoding.py)
MAX_GUIDANCE = 20.0
DEFAULT_RETRIEVAL_PREFIX = 2  # codes of a retrieved clip a seeded candidate starts from (retrieval_seeds.py)
MAX_RETRIEVAL_PREFIX = 12
DEFAULT_RETRIEVED = 2  # real clips nearest by caption added to best-of-N's candidates (retrieved_candidates.py)
MAX_RETRIEVED = 16
DEFAULT_RETRIEVAL_FIRST = None  # caption similarity from which only retrieved clips compete (None: never)


def or_defaults(candidates: int | None = None, retrieved: int | None = None,
                retrieval_first: float | None = None, retrieval_prefix: int | None = None) -> tuple:
    """(candidates, retrieved, retrieval_first, retrieval_prefix), each one not given (None) the product's
    default: what an evaluation samples with unless it is told otherwise."""
    return (DEFAULT_CANDIDATES if candidates is None else candidates,
            DEFAULT_RETRIEVED if retrieved is None else retrieved,
            DEFAULT_RETRIEVAL_FIRST if retrieval_first is None else retrieval_first,
            DEFAULT_RETRIEVAL_PREFIX if retrieval_prefix is None else retrieval_prefix)


def _integer(value, name: str) -> int:
    if isinstance(value, bool):
        raise ShapeMoveError(f"{name} must be a whole number, got {value!r}")
    if isinstance(value, float) and math.isfinite(value) and value == int(value):
        value = int(value)
    if not isinstance(value, int):
        try:
            import numpy as np

            if isinstance(value, np.integer):
                return int(value)
        except ImportError:  # pragma: no cover
            pass
        raise ShapeMoveError(f"{name} must be a whole number, got {str(value)[:40]!r}")
    return value


def _count(value, name: str, lo: int, hi: int, unit: str = "") -> int:
    """A whole number in [lo, hi]; the refusal names ``name`` and the range (in ``unit``)."""
    n = _integer(value, name)
    if not lo <= n <= hi:
        raise ShapeMoveError(f"{name} must be between {lo} and {hi}{' ' + unit if unit else ''}, "
                             f"got {n if abs(n) < 10**9 else 'a huge number'}")
    return n


def _number_or_none(value, what: str, hi: float, lo_text: str = "0") -> float | None:
    """None, or a finite number in [0, hi]; the refusal says "``what`` must be a number from ``lo_text`` to hi"."""
    if value is None:
        return None
    if (isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(float(value))
            or not 0 <= value <= hi):
        raise ShapeMoveError(f"{what} must be a number from {lo_text} to {hi:g}, got {str(value)[:40]!r}")
    return float(value)


def check_sampling(seed, temperature, top_k) -> tuple[int, float, int | None]:
    """(seed, temperature, top_k) validated: seed 0..2**63-1, temperature finite in [0, 100]
    (0 = greedy), top_k None/0 (no limit) or a positive whole number."""
    seed = _integer(seed, "seed")
    if not 0 <= seed <= MAX_SEED:
        raise ShapeMoveError(f"seed must be between 0 and 2**63-1, got {seed if abs(seed) < 10**30 else 'a huge number'}")
    if isinstance(temperature, bool) or not isinstance(temperature, (int, float)):
        raise ShapeMoveError(f"temperature must be a number, got {str(temperature)[:40]!r}")
    temperature = float(temperature)
    if not math.isfinite(temperature) or not 0 <= temperature <= MAX_TEMPERATURE:
        raise ShapeMoveError(f"temperature must be a finite number from 0 (greedy) to {MAX_TEMPERATURE:g}, "
                             f"got {temperature}")
    if top_k is not None:
        top_k = _integer(top_k, "top-k")
        if top_k < 0:
            raise ShapeMoveError(f"top-k must be 0 (no limit) or a positive whole number, got {top_k}")
    return seed, temperature, top_k


def check_candidates(n) -> int:
    """Number of token samples for best-of-N (``rerank.py``): a whole number from 1 (no choice) to
    ``MAX_CANDIDATES``."""
    return _count(n, "candidates", 1, MAX_CANDIDATES)


def check_guidance(s) -> float | None:
    """Classifier-free guidance scale: None (the model's default) or a finite number in [0, MAX_GUIDANCE]."""
    return _number_or_none(s, "guidance", MAX_GUIDANCE, "0 (none)")


def check_retrieval_prefix(n) -> int:
    """Codes of a retrieved clip that seeded candidates start from (``retrieval_seeds.py``): 0 (no
    seeding) to ``MAX_RETRIEVAL_PREFIX``."""
    return _count(n, "retrieval prefix", 0, MAX_RETRIEVAL_PREFIX, "codes")


def check_retrieved(n) -> int:
    """Real clips retrieved as extra candidates (``retrieved_candidates.py``): 0 (none) to ``MAX_RETRIEVED``."""
    return _count(n, "retrieved clips", 0, MAX_RETRIEVED)


def check_retrieval_first(s) -> float | None:
    """None (retrieved clips only compete with the samples) or a caption similarity in [0, 1]."""
    return _number_or_none(s, "retrieval-first similarity", 1.0)
