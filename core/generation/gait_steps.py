"""Steps: how many times a candidate's feet come down, read from its features the same way for a
sample, a retrieved clip and a captured take.

The codec decodes some gaits' codes as a body sliding along with its feet near the floor: of the
ten candidates for "she takes a step back", seven went 2.2-6.4 m with no ankle ever 4 cm off the
floor. A captured take always steps. So:

- a count of steps ("takes three steps backwards") is asked of the candidates whose feet come
  down at least that many times (``striking``), which the stop can be cut after
  (``stop_words.stop_cut``): "a man takes two steps backwards" slid 5.2 m, nothing to cut after;
- a gait asked to go somewhere is asked of the candidates that step at least ``MIN_CADENCE`` times
  a second (``stepping``; a slow walk steps about 1.5 times): "a woman walks backwards and stops"
  slid 2.3 m with no strike at all.

Where no candidate does, all compete.

    foot_strikes(features)                    # feet coming down in a (T, 263) clip
"""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from ..motion.contacts import runs
from .count_words import ANKLES, joint_height

STEP_LIFT = 0.04      # m: an ankle this far over its floor is off it (a walk's: 8-10 cm)
STEP_FRAMES = 3       # frames: the shortest swing counted as a step
FIRST_STRIKE = 5      # frames: a foot that comes down before this was coming down at the start, no step taken
MIN_CADENCE = 0.75    # strikes a second: a gait going somewhere steps at least this often


def foot_strikes(features) -> int:
    """How many times the feet of a (T, 263) feature clip come down: for each ankle, the runs of at
    least ``STEP_FRAMES`` frames it is more than ``STEP_LIFT`` above its own floor (its 10th
    percentile) that end from frame ``FIRST_STRIKE`` on and before the clip does."""
    f = np.asarray(features, dtype=np.float64)
    n = 0
    for joint in ANKLES:
        h = joint_height(f, joint)
        n += sum(1 for a, b in runs(h > np.percentile(h, 10) + STEP_LIFT)
                 if b - a >= STEP_FRAMES and FIRST_STRIKE <= b < len(h))
    return n


def contact_strikes(contacts) -> list[int]:
    """The frames, in order, where a foot comes down in (T, 4) contacts of joints 7, 8, 10, 11: a new
    contact of an ankle (joints 7, 8) from frame ``FIRST_STRIKE`` on (a foot already coming down at
    the start is no step taken)."""
    c = np.asarray(contacts, bool)
    return sorted(a for k in (0, 1) for a, _ in runs(c[:, k]) if a >= FIRST_STRIKE)


def striking(feats: list, steps: int, among: np.ndarray) -> np.ndarray:
    """(N,) bool: of the candidates ``among`` (bool), those whose feet come down at least ``steps``
    times (``foot_strikes``), which a count of steps can be cut after; ``among`` itself where none
    does. "A man takes three steps backwards" chose a backward walk's codes that slid 5.2 m with the
    ankles never 4 cm off the floor: no strike to cut after, so it slid on."""
    if not among.any():
        return among
    keep = among & (np.array([foot_strikes(f) for f in feats]) >= steps)
    return keep if keep.any() else among


def stepping(words, feats: list, among: np.ndarray) -> np.ndarray:
    """(N,) bool: where the words (``plan.words.Words``) ask a gait that goes somewhere (a gait of
    ``plan/part_prompts.LEGS``, not in place or standing still), the candidates ``among`` whose feet
    come down at least ``MIN_CADENCE`` times a second; ``among`` itself otherwise, or where none
    does."""
    from ..plan.part_prompts import LEGS

    if not among.any() or words.in_place or words.stand_still or not any(a in LEGS for a in words.actions):
        return among
    keep = among & np.array([foot_strikes(f) >= MIN_CADENCE * len(f) / FPS for f in feats])
    return keep if keep.any() else among
