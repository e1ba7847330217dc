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
and its feet are planted as for any sample. A clip shorter than the requested length is skipped,
and so is one labelled with another action than the words ask (``Generator._sampled``, by
``captured_takes.action_credit``: "an old man sits down slowly" found an elderly walk). Where the
words name no action the plan knows, a clip competes only when its caption says nearly what the
prompt says (``NAMELESS_FLOOR``, as ``captured_takes.NAMELESS_FLOOR`` for the takes): "a woman does
aerobics" (4 s) walked 5.6 m on an active walk's codes, "a man dodges to the side" 4.9 m on a
veering walk's.
A user's library (``Generator.add_library``) is in the same memory, where thousands of training
captions can be nearer to a prompt than the user's own: ``library_codes`` offers the library's
nearest clip beside them when its caption is nearly as near, and its nearest clip of an action the
prompt names.

    rows = retrieved_codes(t5.memory, reader, "a man throws punches", count=2, min_codes=20, max_codes=20)
"""
from __future__ import annotations

import math

from ..models.motion_memory import sentence_vectors

WINDOWS = 3   # windows of a clip longer than the requested length: its start, middle and end
LIBRARY_MARGIN = 0.08   # a user's library clip competes when its caption is this near the nearest caption's
LIBRARY_FLOOR = 0.4     # ... and at least this near the prompt (MiniLM cosine)
LIBRARY_SHORTEST = 0.5  # a library clip shorter than asked competes whole when it covers this share of the length
NAMELESS_FLOOR = 0.7    # words naming no action: a clip competes from this caption similarity (MiniLM cosine)


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


def library_codes(memory, reader, prompt: str, library, found, min_codes: int, max_codes: int,
                  margin: float = LIBRARY_MARGIN) -> list[tuple[str, float, list[int]]]:
    """(clip id, caption similarity, codes) of the windows of the user's library clips (``library``:
    their clip ids in ``memory``) that compete beside ``found`` (what ``retrieved_codes`` gave):
    the library clip nearest to ``prompt`` by caption when its similarity is at least
    ``LIBRARY_FLOOR`` and at least the memory's nearest caption's (a clip of any length) less
    ``margin``, and the nearest library clip of an action the prompt names (``data/actions.py``
    patterns, read from its caption): thousands of training captions would otherwise keep a user's
    own clip out of the candidates ("a karate front kick" finds the training kicks, not the user's
    "front kick with the right leg"; "a woman kicks" finds "A person kicks."). A library clip
    shorter than ``min_codes`` competes whole when it covers ``LIBRARY_SHORTEST`` of it (most
    captured kicks and punches last under the 4 s a user asks; the generator says so when one is
    kept). Clips already in ``found`` are not offered again; [] when none qualifies."""
    from ..data.actions import action_spans

    if memory is None or not library:
        return []
    min_codes = max(1, math.ceil(LIBRARY_SHORTEST * min_codes))
    mine = [i for i, c in enumerate(memory.clip_ids) if c in library]
    taken = {f[0] for f in found}
    offered = []
    v = sentence_vectors(reader, [prompt])
    hit = memory.nearest_of(v[0], mine, min_codes)
    if hit is not None:
        near = max((s for _, s in memory.nearest(v, 1)[0]), default=hit[1])   # the nearest caption, any length
        if hit[1] >= max(LIBRARY_FLOOR, near - margin):
            offered.append(hit)
    named = {a for _, _, a in action_spans(prompt)}
    hit = memory.nearest_of(v[0], [i for i in mine if named & set(memory.clip_actions[i])], min_codes)
    if hit is not None:
        offered.append(hit)
    out = []
    for c, sim in offered:
        cid = memory.clip_ids[c]
        if cid not in taken:
            taken.add(cid)
            out += [(cid, float(sim), w) for w in windows(memory.clip_tokens[c], min_codes, max_codes)]
    return out
