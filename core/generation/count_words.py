"""How many times the words ask for a jump, a squat or a kick: "jumps twice", "a person jumps three
times", "does five jumping jacks", "she hops once", "does three squats", "kicks twice".

The T5 writes jumps and squats, but not how many: the default model gave "a man jumps forward
twice" one, two or three jumps by seed, and the TMA that chooses among the candidates (``rerank``)
does not count. Its candidates differ in how many times they leave the floor or go down, so when
the plan names a countable action (``plan/vocabulary.COUNTED``) and a count, only the candidates
whose count is nearest the asked one compete. The counts are read from the candidate's features,
the same way for a generated candidate, a retrieved clip and a captured take (which
``repeated_takes.py`` cuts to the repetitions asked):

- a flight (jumps, hops): a run of at least ``MIN_RUN`` frames in which every foot joint (both
  ankles and both toes) is more than ``LIFT`` above the clip's floor;
- a raise (jumping jacks): a run of at least ``MIN_RUN`` frames with both wrists above the head
  (a captured jumping jack lifts the feet 5-10 cm, under what a jump's flight clears, but every
  jack brings both hands over the head);
- a dip (squats): a run of at least ``MIN_RUN`` frames with the root more than ``DIP`` under its
  standing height (the clip's 90th percentile);
- a kick: a run of at least ``MIN_RUN`` frames with one ankle more than ``KICK_LIFT`` above the
  floor and the other under ``KICK_STANCE`` (each of the 16 single front kicks of the built-in
  library counts one; a run, whose heels swing high, is not asked to kick).

    read_words("a man jumps forward twice").count   # ("jump forward", 2)  (plan/words.py)
    counter("jump forward")(features)               # flights of a (T, 263) candidate
    repetitions("squat", features)                  # [(start, end)) of each squat
"""
from __future__ import annotations

import numpy as np

from ..motion.contacts import runs
from ..plan.vocabulary import COUNTED

FOOT_JOINTS = (7, 8, 10, 11)   # ankles, toes
ANKLES = (7, 8)
WRISTS, HEAD = (20, 21), 15
LIFT = 0.08                    # metres over the floor (the clip's 10th percentile of its lowest foot joint)
DIP = 0.20                     # metres under the standing root height
MIN_RUN = 3                    # frames (0.15 s)
KICK_LIFT = 0.45               # metres: a kicking ankle over the floor (a captured front kick's: 0.9-1.4 m)
KICK_STANCE = 0.30             # metres: the standing foot under this (it rises on its toes as the other kicks)


def _spans(mask) -> list[tuple[int, int]]:
    return [(a, b) for a, b in runs(mask) if b - a >= MIN_RUN]


def joint_height(f, joint: int) -> np.ndarray:
    """(T,) height (m) of joint ``joint`` (1..21) in (T, 263) features (its root-relative position channels)."""
    return f[:, 4 + (joint - 1) * 3 + 1]


def flight_spans(features) -> list[tuple[int, int]]:
    """[(start, end)) of the flights of a (T, 263) feature clip: runs of at least ``MIN_RUN``
    frames with every foot joint more than ``LIFT`` above the clip's floor."""
    f = np.asarray(features, dtype=np.float64)
    heights = np.stack([joint_height(f, j) for j in FOOT_JOINTS], axis=1).min(axis=1)
    return _spans(heights > np.percentile(heights, 10) + LIFT)


def raise_spans(features) -> list[tuple[int, int]]:
    """[(start, end)) of the raises of both hands over the head: runs of at least ``MIN_RUN`` frames
    with both wrists above the head joint."""
    f = np.asarray(features, dtype=np.float64)
    wrists = np.minimum(joint_height(f, WRISTS[0]), joint_height(f, WRISTS[1]))
    return _spans(wrists > joint_height(f, HEAD))


def dip_spans(features) -> list[tuple[int, int]]:
    """[(start, end)) of the squats of a (T, 263) feature clip: runs of at least ``MIN_RUN`` frames
    with the root more than ``DIP`` under its standing height."""
    y = np.asarray(features, dtype=np.float64)[:, 3]
    return _spans(y < np.percentile(y, 90) - DIP)


def kick_spans(features) -> list[tuple[int, int]]:
    """[(start, end)) of the kicks of a (T, 263) feature clip: runs of at least ``MIN_RUN`` frames with
    one ankle more than ``KICK_LIFT`` above the clip's floor while the other stays under
    ``KICK_STANCE`` (a run's heels also swing high, but both feet are never down then for long)."""
    f = np.asarray(features, dtype=np.float64)
    feet = np.stack([joint_height(f, j) for j in FOOT_JOINTS], axis=1)
    floor = np.percentile(feet.min(axis=1), 10)
    left, right = joint_height(f, ANKLES[0]) - floor, joint_height(f, ANKLES[1]) - floor
    spans = _spans((left > KICK_LIFT) & (right < KICK_STANCE)) + _spans((right > KICK_LIFT) & (left < KICK_STANCE))
    return sorted(spans)


MEASURES = {"flights": flight_spans, "raises": raise_spans, "dips": dip_spans,
            "kicks": kick_spans}   # ``plan/vocabulary.COUNTED``'s


def repetitions(action: str, features) -> list[tuple[int, int]]:
    """[(start, end)) of each repetition of a countable action (``plan/vocabulary.COUNTED``) in a
    (T, 263) feature clip."""
    return MEASURES[COUNTED[action]](features)


def counter(action: str):
    """How many times a countable action is done in a feature clip: ``counter(action)(features)``."""
    return lambda features: len(repetitions(action, features))


def nearest_count(counts, want: int, among: np.ndarray) -> np.ndarray:
    """(N,) bool: the candidates ``among`` whose count is nearest ``want``."""
    among = np.asarray(among, bool)
    if not among.any():
        return among
    off = np.abs(np.asarray(counts, np.int64) - want)
    return among & (off == off[among].min())
