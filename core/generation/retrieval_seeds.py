"""Retrieval-seeded candidates: some of best-of-N's token samples start from the first codes of the
real clips whose captions are nearest to the prompt.

The T5 reads the retrieved clips as memory, but a small decoder still falls back to the frequent
motions it learnt best (a walk, a raised hand) when the prompt asks for a rarer one (a punch, a
throw). Here the decoder is also *shown* how a retrieved clip starts: ``prefix`` codes (0.4 s for
2 codes at 20 fps, 4x downsampling) are written after ``[SOM]`` and the decoder continues from
them (``constrained_decoding.decode(prefix_codes=...)``, one prefix per row). Only the
continuation is kept, so the motion is the model's, on the requested body and length; the TMA then
picks among these and the unseeded samples (``rerank.CandidatePicker``).

    rows = seed_prefixes(t5.memory, reader, "a man throws a jab", count=4, prefix=2)
"""
from __future__ import annotations

SEEDED_SHARE = 0.5   # share of best-of-N's candidates that start from a retrieved clip


def seed_prefixes(memory, reader, prompt: str, count: int, prefix: int) -> list[list[int]]:
    """Up to ``count`` lists of ``prefix`` codes: the starts of the distinct clips nearest to
    ``prompt`` by caption (MiniLM cosine), nearest first; clips shorter than ``prefix`` + 1 codes
    are skipped. [] without a memory, for ``count`` or ``prefix`` 0, or an empty memory."""
    if memory is None or count <= 0 or prefix <= 0 or not len(memory):
        return []
    near = memory.nearest_long(reader, prompt, count, prefix + 1, 2 * count)  # room for skipping short clips
    return [[int(x) for x in memory.clip_tokens[c][:prefix]] for c, _ in near]


def seeded_count(candidates: int) -> int:
    """How many of ``candidates`` samples start from a retrieved clip (none for a single sample)."""
    return int(candidates * SEEDED_SHARE) if candidates > 1 else 0
