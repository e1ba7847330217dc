"""The pace the words ask of a gait: "walks quickly", "a brisk walk", "runs as fast as they can",
"walks slowly".

The words are read by the plan (``plan/words.py``: ``Words.pace``, ``Words.slow_flight``). The TMA that chooses among the candidates (``rerank.CandidatePicker``) hardly tells a brisk walk
from a slow one, and the clips retrieved for "walks quickly" by caption can be slow ones: the
default model gave "a person walks quickly" 0.51 m/s against 1.08 m/s for "a person walks"
(``tools/pace_check.py``). So when a prompt names a gait (the legs actions of
``plan/part_prompts.LEGS``: walk, jog, run, march, sneak, ...) and a fast pace, only the fastest third
of the candidates compete. Speed is the root's mean horizontal speed along its path, read from
the features' root velocities.

A slow pace is not chosen among the candidates: the slowest candidates of a walk are often limps
and creeps, so choosing them cost the gait (``docs/design-notes.md``, Prompts). Instead the
chosen motion of a stepping gait (a walk, march, sneak, limp, ...: no flight phase) is played at
``SLOW_SPEED`` over the same length (``slow_steps.slow_motion``: an edit, like a turn the words
name). A jog or a run asked slowly keeps its cadence and flights and takes ``SLOW_SPEED`` shorter
strides (played slower, its flights would hang in the air). Both
paces named ("slowly, then fast") is no pace; a prompt without a gait ("waves quickly") is left to
the TMA, since its root speed says nothing of a hand's. Whatever the pace, a gait asked to go
somewhere is not given a candidate that stands about (``going``: slower than ``STANDING_SPEED``),
and an exercise or a gesture asked with no travel not one that walks off (``staying``: as fast
as ``WANDER_SPEED`` or faster), nor any other action but a gait one that runs off (``RUN_OFF_SPEED``).
"""
from __future__ import annotations

import numpy as np

from ..constants import FPS

FAST_SHARE = 1 / 3  # the fastest third of the candidates compete for a fast pace
SLOW_SPEED = 0.8    # a stepping gait asked slowly is played at this speed
STANDING_SPEED = 0.25   # m/s: a candidate of a gait asked to go on slower than this stands about
WANDER_SPEED = 0.5      # m/s: a candidate of an action done where one stands this fast walks off
RUN_OFF_SPEED = 1.6     # m/s: a candidate of any other action but a gait this fast runs off (the built-in
                        # library's fastest take of one: a dribble down the court, 1.44 m/s)
STAYING_GROUPS = ("exercise", "gesture")   # the vocabulary's groups of actions done where one stands

def path_length(features: np.ndarray) -> float:
    """Metres the root travels along its path over a (T, 263) feature clip (its horizontal
    velocities, metres a frame, ``features.py``, summed)."""
    f = np.asarray(features, dtype=np.float64)
    return float(np.hypot(f[:, 1], f[:, 2]).sum())


def gait_speed(features: np.ndarray) -> float:
    """Mean horizontal root speed (m/s) along the path of a (T, 263) feature clip."""
    return path_length(features) / max(len(features), 1) * FPS


def fastest(speeds: np.ndarray, among: np.ndarray) -> np.ndarray:
    """(N,) bool: the fastest third (``FAST_SHARE``) of the candidates ``among`` (bool), at or above
    the quantile's speed; ``among`` itself when it holds none."""
    speeds = np.asarray(speeds, dtype=np.float64)
    if not among.any():
        return among
    keep = among & (speeds >= np.quantile(speeds[among], 1 - FAST_SHARE))
    return keep if keep.any() else among


def going(words, speeds: np.ndarray, among: np.ndarray) -> np.ndarray:
    """(N,) bool: where the words (``plan.words.Words``) ask a gait that goes somewhere (a gait of
    ``plan/part_prompts.LEGS``; not in place, standing still, steps or a distance counted), the
    candidates ``among`` that go at ``STANDING_SPEED`` or faster; ``among`` itself otherwise, or when
    none does. The TMA chose for "a person walks to the door" a sample that went 0.5 m in 3 s."""
    from ..plan.part_prompts import LEGS

    if not among.any() or words.in_place or words.stand_still or words.steps is not None or \
            words.distance_m is not None or not any(a in LEGS for a in words.actions):
        return among
    keep = among & (np.asarray(speeds, dtype=np.float64) >= STANDING_SPEED)
    return keep if keep.any() else among


def staying(words, speeds: np.ndarray, among: np.ndarray) -> np.ndarray:
    """(N,) bool: where the words (``plan.words.Words``) ask only actions done where one stands (the
    vocabulary's ``STAYING_GROUPS``: an exercise, a gesture: arm circles, a side twist, a wave; and
    its ``POSTURE_CHANGES``: sitting down, lying down, getting up) and no travel, the candidates ``among``
    slower than ``WANDER_SPEED``; where they ask only actions that are no gait (a dance, a kick, a
    jump forward, a climb), those slower than ``RUN_OFF_SPEED``; ``among`` itself otherwise, or when
    none is. "A woman twists her torso side to side" chose a sample that walked sideways 4.8 m
    (retrieved for "side to side"), "a man swings his arms in circles" a take walking 5 m, "an old
    man sits down slowly" a sample walking 2 m that never sat, "the robot busts a move" (a dance) a
    sample running 13 m."""
    from ..data.actions import ACTIONS
    from ..plan.vocabulary import POSTURE_CHANGES

    if not among.any() or not words.actions or words.travel.named or words.course is not None:
        return among
    if all(a in POSTURE_CHANGES or a in ACTIONS and ACTIONS[a].group in STAYING_GROUPS for a in words.actions):
        limit = WANDER_SPEED
    elif all(a in ACTIONS and ACTIONS[a].group != "locomotion" for a in words.actions):
        limit = RUN_OFF_SPEED
    else:
        return among
    keep = among & (np.asarray(speeds, dtype=np.float64) < limit)
    return keep if keep.any() else among
