"""A captured take of a counted action played for its repetitions: "a woman does three jumping
jacks" plays three jacks; "a woman does jumping jacks" plays the take's jacks, not the side
twists and stretches that follow them in the same capture.

A take whose action is counted (``plan/vocabulary.COUNTED``: jumps, hops, jumping jacks, squats)
is cut at its repetitions, found on the take posed on its performer's body by the measure that
counts them in any candidate (``count_words.repetitions``):

- its repetitions fall into bouts (neighbours at most ``BOUT_GAP`` s apart); the bout with the
  most (the first of equals) is what plays, from half the gap between its repetitions before its
  first to as much after its last (``LONE_PAD`` s for a lone repetition), never past halfway to a
  repetition outside it nor past the take; a repetition the take's end cuts short is none;
- asked a number (``times``), the bout is cut to that many repetitions in a row (which ones: drawn
  by the seed), between two repetitions halfway; a bout with fewer plays on as a loop of its own
  cycle first (``take_loop.looped_take``, else ``looped_repetition``: one squat squatted again)
  and is measured and cut again. The caller then holds its last pose for the rest of the window;
  a take that cannot give the number plays its bout as it is, and the candidates' counts decide
  (``rerank``);
- asked no number, the bout plays as any take does (the busiest window, a loop, a hold); a kick,
  done once by its nature, is not cut then (``WHEN_ASKED``): its take plays as any other.

    rot, root, con, exact = repeated_stretch(rot, root, con, posed, "jumping jacks", 3, seed=0)
    # posed(rot, root, con) -> ((T, J, 3) joints, (T - 1, 263) features) on the performer's body
"""
from __future__ import annotations

import random

from ..constants import FPS
from .count_words import repetitions

BOUT_GAP = 2.0   # s: repetitions further apart than this are different bouts
LONE_PAD = 1.0   # s kept on either side of a lone repetition
WHEN_ASKED = ("kick",)   # done once by its nature: cut to its repetitions only when a number is asked


def cut_for(action: str, times: int | None) -> bool:
    """Whether a take of ``action`` is cut to its repetitions: a counted action
    (``plan/vocabulary.COUNTED``), and for one done once by its nature (a kick: its take's busiest
    window plays otherwise) only when a number is asked."""
    from ..plan.vocabulary import COUNTED

    return action in COUNTED and (times is not None or action not in WHEN_ASKED)


def bouts(spans, gap: int) -> list[list[tuple[int, int]]]:
    """The repetitions ``spans`` [(start, end)) grouped: a neighbour starting at most ``gap``
    frames after the previous one's end joins its bout."""
    out: list[list[tuple[int, int]]] = []
    for s in spans:
        if out and s[0] - out[-1][-1][1] <= gap:
            out[-1].append(s)
        else:
            out.append([s])
    return out


def _bounds(spans, k: int, m: int, n: int, pad: int) -> tuple[int, int]:
    """Frames [lo, hi) holding repetitions k..m-1 of ``spans``: ``pad`` frames either side, never
    past halfway to a neighbouring repetition nor outside 0..n."""
    lo, hi = max(0, spans[k][0] - pad), min(n, spans[m - 1][1] + pad)
    if k > 0:
        lo = max(lo, (spans[k - 1][1] + spans[k][0]) // 2)
    if m < len(spans):
        hi = min(hi, (spans[m - 1][1] + spans[m][0] + 1) // 2)
    return lo, hi


def _pad(bout) -> int:
    """Frames kept either side of a bout: half the mean gap between its repetitions."""
    if len(bout) < 2:
        return int(LONE_PAD * FPS)
    return max(1, sum(b[0] - a[1] for a, b in zip(bout, bout[1:])) // (len(bout) - 1) // 2)


def _complete(action: str, features) -> list[tuple[int, int]]:
    """The repetitions of ``action`` in ``features``, but one the clip's end cuts short."""
    return [s for s in repetitions(action, features) if s[1] < len(features)]


def repeated_stretch(rotations, root, contacts, posed, action: str, times: int | None, seed: int):
    """(rotations, root, contacts, exact): the take cut to its longest bout of ``action``'s
    repetitions, and to ``times`` of them when asked (``exact`` True when it holds that many);
    the take as it is when it holds none. ``posed(rot, root, con) -> (joints, features)``."""
    from .take_loop import looped_repetition, looped_take

    spans = _complete(action, posed(rotations, root, contacts)[1])
    if not spans:
        return rotations, root, contacts, False
    groups = bouts(spans, int(BOUT_GAP * FPS))
    best = max(range(len(groups)), key=lambda g: (len(groups[g]), -g))
    k = sum(len(g) for g in groups[:best])
    bout = groups[best]
    lo, hi = _bounds(spans, k, k + len(bout), len(rotations), _pad(bout))
    rot, rt, con = rotations[lo:hi], root[lo:hi], contacts[lo:hi]
    bout = [(a - lo, b - lo) for a, b in bout]
    if times is None:
        return rot, rt, con, False
    if len(bout) < times:   # played on as a loop of its own cycle, then measured again
        frames = len(rot) * -(-(times + 1) // len(bout))   # room for one more than asked
        joints = posed(rot, rt, con)[0]
        again = looped_take(rot, rt, con, joints, frames) or looped_repetition(rot, rt, con, joints, frames)
        if again is None:
            return rot, rt, con, False
        longer = again[:3]
        found = _complete(action, posed(*longer)[1])
        if len(found) < times:
            return rot, rt, con, False
        rot, rt, con = longer
        bout = found
    k = random.Random(int(seed)).randrange(len(bout) - times + 1)
    lo, hi = _bounds(bout, k, k + times, len(rot), _pad(bout))
    return rot[lo:hi], rt[lo:hi], con[lo:hi], True
