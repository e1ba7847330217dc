"""How many times the words ask for a jump: "jumps twice", "a person jumps three times", "does
five jumping jacks", "she hops once".

The T5 writes jumps, but not how many: the default model gave "a man jumps forward twice" one,
two or three jumps by seed, and the TMA that chooses among the candidates (``rerank``) does not
count. Its candidates differ in how many times they leave the floor, so when a prompt names a
jump (``JUMPS``) and a count, only the candidates whose count of flights is nearest the asked one
compete. A flight is a run of at least ``MIN_FLIGHT`` frames in which every foot joint (both ankles
and both toes) is more than ``LIFT`` above the clip's floor, read from the candidate's features
(their joint heights), the same way for a generated candidate and a retrieved clip.

    asked_jumps("a man jumps forward twice")    # 2
    flights(features)                           # flights of a (T, 263) candidate
"""
from __future__ import annotations

import re

import numpy as np

from ..data.actions import action_spans
from ..motion.contacts import runs

JUMPS = {"jump", "jump forward", "spin jump", "hop", "jumping jacks"}
FOOT_JOINTS = (7, 8, 10, 11)   # ankles, toes
LIFT = 0.08                    # metres over the floor (the clip's 10th percentile of its lowest foot joint)
MIN_FLIGHT = 3                 # frames (0.15 s)
MAX_COUNT = 12

_NUMBER = {"once": 1, "one": 1, "a single": 1, "twice": 2, "two": 2, "a couple of": 2, "thrice": 3, "three": 3,
           "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10}
_WORD = "|".join(sorted(map(re.escape, _NUMBER), key=len, reverse=True))
_COUNT = re.compile(rf"\b(?:(once|twice|thrice)|({_WORD}|\d{{1,2}})\s+(?:times\b|(?:\w+\s+)?(?:jump|hop|leap)\w*))", re.I)


def asked_jumps(prompt: str) -> int | None:
    """The number of jumps ``prompt`` asks for, when it names a jump and counts it; None otherwise
    (also for a count beyond ``MAX_COUNT`` or of zero)."""
    if not {sp[2] for sp in action_spans(prompt)} & JUMPS:
        return None
    m = _COUNT.search(prompt)
    if m is None:
        return None
    word = (m.group(1) or m.group(2)).lower()
    n = int(word) if word.isdigit() else _NUMBER[word]
    return n if 1 <= n <= MAX_COUNT else None


def flights(features) -> int:
    """Flights in a (T, 263) feature clip: runs of at least ``MIN_FLIGHT`` frames with every foot
    joint more than ``LIFT`` above the clip's floor."""
    f = np.asarray(features, dtype=np.float64)
    heights = np.stack([f[:, 4 + (j - 1) * 3 + 1] for j in FOOT_JOINTS], axis=1).min(axis=1)
    air = heights > np.percentile(heights, 10) + LIFT
    return sum(1 for a, b in runs(air) if b - a >= MIN_FLIGHT)


def nearest_count(counts, want: int, among: np.ndarray) -> np.ndarray:
    """(N,) bool: the candidates ``among`` whose count is nearest ``want``."""
    among = np.asarray(among, bool)
    if not among.any():
        return among
    off = np.abs(np.asarray(counts, np.int64) - want)
    return among & (off == off[among].min())
