"""Retrieved candidates: real clips of the model's memory whose captions are nearest to the prompt,
offered to best-of-N beside the generated samples, or instead of them when a caption is as good as
the prompt itself.

The T5 writes the frequent motions well and the rare ones (a march, a sidestep, a punch) poorly:
its samples fall back to a walk or a raised hand. The model folder's memory
(``models/motion_memory.py``: the tokens of the real captured training clips and their mirror
images, with their captions) holds performances of every action. Here the ``count`` clips whose
caption is nearest to the prompt (MiniLM cosine, distinct clips) join the candidates, their tokens
cut to the requested length; the TMA then picks among all of them (``rerank.CandidatePicker``), so
a retrieved clip is kept only when it matches the prompt better than every sample. When the
nearest caption's similarity reaches ``retrieval_first`` (a prompt the data describes almost word
for word), only the retrieved windows compete: the TMA rates a generated fallback (a raised hand)
about as close to "throws punches" as a captured punch, so best-of-N alone would keep it. Either way the
tokens are decoded by the SA-VAE for the requested body, so the motion has that body's proportions
and its feet are planted as for any sample. A clip shorter than the requested length is skipped.

    rows = retrieved_codes(t5.memory, reader, "a man throws punches", count=2, min_codes=20, max_codes=20)
"""
from __future__ import annotations

WINDOWS = 3   # windows of a clip longer than the requested length: its start, middle and end


def windows(codes, min_codes: int, max_codes: int) -> list[list[int]]:
    """A clip's codes cut to the requested length: the whole clip when it fits, else ``WINDOWS``
    windows of ``max_codes`` (start, middle, end: a captured take often starts and ends standing);
    [] when it is shorter than ``min_codes``."""
    c = [int(x) for x in codes]
    if len(c) < min_codes:
        return []
    if len(c) <= max_codes:
        return [c]
    starts = sorted({round(i * (len(c) - max_codes) / (WINDOWS - 1)) for i in range(WINDOWS)})
    return [c[s:s + max_codes] for s in starts]


def retrieved_codes(memory, reader, prompt: str, count: int, min_codes: int,
                    max_codes: int) -> list[tuple[str, float, list[int]]]:
    """(clip id, caption similarity, codes) of the windows of up to ``count`` distinct clips nearest
    to ``prompt`` by caption, nearest first; clips shorter than ``min_codes`` are skipped. [] without
    a memory or for ``count`` 0."""
    if memory is None or count <= 0 or not len(memory):
        return []
    out = []
    for c, sim in memory.nearest_long(reader, prompt, count, min_codes, 4 * count):  # room for skipping short clips
        out += [(memory.clip_ids[c], float(sim), w) for w in windows(memory.clip_tokens[c], min_codes, max_codes)]
    return out
