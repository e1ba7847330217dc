"""How many times the words ask for a jump or a squat: "jumps twice", "a person jumps three
times", "does five jumping jacks", "she hops once", "does three squats".

The T5 writes jumps and squats, but not how many: the default model gave "a man jumps forward
twice" one, two or three jumps by seed, and the TMA that chooses among the candidates (``rerank``)
does not count. Its candidates differ in how many times they leave the floor or go down, so when
a prompt names a countable action (``COUNTERS``) and a count, only the candidates whose count is
nearest the asked one compete. Both counts are read from the candidate's features, the same way
for a generated candidate and a retrieved clip:

- a flight (jumps, hops, jumping jacks): a run of at least ``MIN_RUN`` frames in which every foot
  joint (both ankles and both toes) is more than ``LIFT`` above the clip's floor;
- a dip (squats): a run of at least ``MIN_RUN`` frames with the root more than ``DIP`` under its
  standing height (the clip's 90th percentile).

    asked_count("a man jumps forward twice")    # (flights, 2)
    flights(features), dips(features)           # of a (T, 263) candidate
"""
from __future__ import annotations

import re

import numpy as np

from ..data.actions import action_spans
from ..motion.contacts import runs

FOOT_JOINTS = (7, 8, 10, 11)   # ankles, toes
LIFT = 0.08                    # metres over the floor (the clip's 10th percentile of its lowest foot joint)
DIP = 0.20                     # metres under the standing root height
MIN_RUN = 3                    # frames (0.15 s)
MAX_COUNT = 12

NUMBERS = {"a": 1, "one": 1, "a single": 1, "two": 2, "a couple of": 2, "a couple": 2, "three": 3, "a few": 3,
           "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10}   # "three steps" too
TIMES = {"once": 1, "twice": 2, "thrice": 3}
# the number words as a regex alternation, longest first; QUANTITY without "a" ("a person jumps" counts nothing)
NUMBER_WORDS = "|".join(sorted(map(re.escape, NUMBERS), key=len, reverse=True))
QUANTITY = "|".join(sorted(map(re.escape, set(NUMBERS) - {"a"}), key=len, reverse=True))
_COUNT = re.compile(rf"\b(?:(once|twice|thrice)|({QUANTITY}|\d{{1,2}})\s+(?:times\b|(?:\w+\s+)?(?:jump|hop|leap|squat)\w*))",
                    re.I)


def _runs_of(mask) -> int:
    return sum(1 for a, b in runs(mask) if b - a >= MIN_RUN)


def flights(features) -> int:
    """Flights in a (T, 263) feature clip: runs of at least ``MIN_RUN`` frames with every foot
    joint more than ``LIFT`` above the clip's floor."""
    f = np.asarray(features, dtype=np.float64)
    heights = np.stack([f[:, 4 + (j - 1) * 3 + 1] for j in FOOT_JOINTS], axis=1).min(axis=1)
    return _runs_of(heights > np.percentile(heights, 10) + LIFT)


def dips(features) -> int:
    """Squats in a (T, 263) feature clip: runs of at least ``MIN_RUN`` frames with the root more
    than ``DIP`` under its standing height."""
    y = np.asarray(features, dtype=np.float64)[:, 3]
    return _runs_of(y < np.percentile(y, 90) - DIP)


COUNTERS = {"jump": flights, "jump forward": flights, "spin jump": flights, "hop": flights,
            "jumping jacks": flights, "squat": dips}


def asked_count(prompt: str):
    """(counter, n): how ``prompt``'s countable action is counted (``COUNTERS``) and how many
    times it asks for it; None when it names none, no count, or a count beyond ``MAX_COUNT``."""
    named = [sp[2] for sp in action_spans(prompt) if sp[2] in COUNTERS]
    m = _COUNT.search(prompt)
    if not named or m is None:
        return None
    word = (m.group(1) or m.group(2)).lower()
    n = int(word) if word.isdigit() else {**NUMBERS, **TIMES}[word]
    return (COUNTERS[named[0]], n) if 1 <= n <= MAX_COUNT else None


def nearest_count(counts, want: int, among: np.ndarray) -> np.ndarray:
    """(N,) bool: the candidates ``among`` whose count is nearest ``want``."""
    among = np.asarray(among, bool)
    if not among.any():
        return among
    off = np.abs(np.asarray(counts, np.int64) - want)
    return among & (off == off[among].min())
