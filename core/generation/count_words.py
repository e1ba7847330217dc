"""How many times the words ask for a jump or a squat: "jumps twice", "a person jumps three
times", "does five jumping jacks", "she hops once", "does three squats".

The T5 writes jumps and squats, but not how many: the default model gave "a man jumps forward
twice" one, two or three jumps by seed, and the TMA that chooses among the candidates (``rerank``)
does not count. Its candidates differ in how many times they leave the floor or go down, so when
the plan names a countable action (``plan/vocabulary.COUNTED``) and a count, only the candidates whose count is
nearest the asked one compete. Both counts are read from the candidate's features, the same way
for a generated candidate and a retrieved clip:

- a flight (jumps, hops, jumping jacks): a run of at least ``MIN_RUN`` frames in which every foot
  joint (both ankles and both toes) is more than ``LIFT`` above the clip's floor;
- a dip (squats): a run of at least ``MIN_RUN`` frames with the root more than ``DIP`` under its
  standing height (the clip's 90th percentile).

    read_words("a man jumps forward twice").count   # ("jump forward", 2)  (plan/words.py)
    counter("jump forward")(features)               # flights of a (T, 263) candidate
"""
from __future__ import annotations

import numpy as np

from ..motion.contacts import runs
from ..plan.vocabulary import COUNTED

FOOT_JOINTS = (7, 8, 10, 11)   # ankles, toes
LIFT = 0.08                    # metres over the floor (the clip's 10th percentile of its lowest foot joint)
DIP = 0.20                     # metres under the standing root height
MIN_RUN = 3                    # frames (0.15 s)


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


MEASURES = {"flights": flights, "dips": dips}   # the measures of ``plan/vocabulary.COUNTED``


def counter(action: str):
    """The measure that counts a countable action (``plan/vocabulary.COUNTED``) in a feature clip."""
    return MEASURES[COUNTED[action]]


def nearest_count(counts, want: int, among: np.ndarray) -> np.ndarray:
    """(N,) bool: the candidates ``among`` whose count is nearest ``want``."""
    among = np.asarray(among, bool)
    if not among.any():
        return among
    off = np.abs(np.asarray(counts, np.int64) - want)
    return among & (off == off[among].min())
