"""The courses the words name, as shapes and times: no motion, no torch (``--explain`` and the panel
read the times without loading a model; ``course_walk.py`` walks a track along them).

A course is one heading profile over a period of it (``Course.heading``: the yaw at a fraction u of
the period, turning left positive, 0 at u = 0) and the period's length for a motion that travels so
far (``Course.period_for``); ``COURSES`` holds the circle, the figure eight, back and forth, the
zigzag, the square, the diagonal and a gait to one side (``course_walk.py`` says how each is walked). With no
length asked, a course that goes round gets the time to go once round at its gait's typical pace
(``course_seconds``, ``unasked_seconds``); ``round_share`` is how much of once round a motion that
travels so far goes.

    course_seconds(CIRCLE, 1.194)                     # 5.85: a circle walked once round
    model_course_seconds()(read_words("she jogs in a circle"))   # 4.46, the default model's jog
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..plan.vocabulary import (ASIDE_COURSE as ASIDE, BACK_AND_FORTH_COURSE as BACK_AND_FORTH, CIRCLE,
                               COURSE_ACTIONS as ACTIONS, DIAGONAL_COURSE as DIAGONAL, EIGHT, SQUARE_COURSE as SQUARE,
                               ZIGZAG_COURSE as ZIGZAG)

MIN_RADIUS, MAX_RADIUS = 1.0, 3.0   # m: a circle's, an eight's loops'
U_RADIUS = 0.3                      # m: back and forth's U-turns
LEG_MIN, LEG_MAX = 1.0, 5.0         # m: back and forth's legs
ZIG, ZIG_ANGLE, ZIG_TURN = 1.5, np.pi / 4, 0.15   # m, radians, share of a leg
SIDE_MIN, SIDE_MAX, CORNER = 1.5, 4.0, 0.6        # m: a square's sides, and the walk round each corner
DIAGONAL_ANGLE, DIAGONAL_EASE = np.pi / 4, 0.6   # radians, m
ASIDE_ANGLE, ASIDE_EASE = np.pi / 2, 1.2         # radians, m
STEP = 0.005                        # m: a course's heading integrated at this step
UNASKED_PACE = 0.9                  # no length asked: once round at this share of the gait's typical pace
UNASKED_LEAST, UNASKED_MOST = 4.0, 12.0   # s: and within these
WALK_SPEED = 1.2                    # m/s: a walk's pace where the model folder has no typical pace table
STOP_SECONDS = 1.0                  # standing after a distance gone (``unasked_seconds``)


def radius_for(distance: float) -> float:
    """The radius (m) of a circle once round in ``distance`` metres, within MIN..MAX_RADIUS."""
    return float(np.clip(distance / (2 * np.pi), MIN_RADIUS, MAX_RADIUS))


def _leg_for(distance: float) -> float:
    """Back and forth's leg (m): once out and back in ``distance`` metres, within LEG_MIN..LEG_MAX."""
    return float(np.clip(distance / 2 - np.pi * U_RADIUS, LEG_MIN, LEG_MAX))


def _circle(u, period):
    return 2 * np.pi * u


def _eight(u, period):
    return 2 * np.pi * (1.0 - np.abs(1.0 - 2.0 * u))


def _stadium(u, period):
    """Out, a U-turn of U_RADIUS, back, a U-turn: the legs fill what the U-turns leave of the period."""
    turn = min(np.pi * U_RADIUS / period, 0.5)       # each U-turn's share of the period
    leg = 0.5 - turn
    return np.pi * (np.clip((u - leg) / turn, 0.0, 1.0) + np.clip((u - 2 * leg - turn) / turn, 0.0, 1.0))


def _square(u, period):
    """Four equal sides, a quarter turn left at the end of each, walked round over ``CORNER``
    metres (eased): from the start of a side, back to it after the fourth corner."""
    w = min(CORNER / period, 0.2)                     # one corner's share of the period
    return 0.5 * np.pi * sum(_ease((u - k / 4 + w) / w) for k in range(1, 5))


def _ease(x):
    """0 -> 1 over x in [0, 1] (half a cosine), 0 before, 1 after."""
    return 0.5 - 0.5 * np.cos(np.pi * np.clip(x, 0.0, 1.0))


def _zigzag(u, period):
    """Half a period at +ZIG_ANGLE, half at -ZIG_ANGLE, the turns between them eased (cosine) over
    ZIG_TURN of a leg, from and back to straight ahead at the period's ends."""
    w = ZIG_TURN / 2                                  # one turn's share of the period
    return ZIG_ANGLE * (_ease(u / (w / 2)) - 2 * _ease((u - 0.5 + w / 2) / w) + _ease((u - 1 + w / 2) / (w / 2)))


def _veer(angle: float, ease: float) -> Callable:
    """A heading profile that turns to ``angle`` over the first ``ease`` metres and keeps it; its
    period is longer than any motion (``COURSES``), so it never starts again."""
    return lambda u, period: angle * _ease(u * period / ease)


@dataclass(frozen=True)
class Course:
    """``heading(u, period)``: the yaw (radians, left positive) at fractions ``u`` in [0, 1] of a
    period ``period`` metres long, 0 at u = 0 and ``net`` at u = 1; ``period_for(distance)``: the
    period (m) for a motion that travels ``distance`` metres."""
    heading: Callable
    net: float
    period_for: Callable[[float], float]

    def yaw(self, s, period: float, right: bool) -> np.ndarray:
        """The course's yaw at distances ``s`` (m) along it, periods of ``period`` m repeated."""
        n, u = np.divmod(np.asarray(s, np.float64) / period, 1.0)
        return (-1.0 if right else 1.0) * (self.heading(u, period) + self.net * n)


COURSES = {
    CIRCLE: Course(_circle, 2 * np.pi, lambda d: 2 * np.pi * radius_for(d)),
    EIGHT: Course(_eight, 0.0, lambda d: 4 * np.pi * radius_for(d / 2)),
    BACK_AND_FORTH: Course(_stadium, 2 * np.pi, lambda d: 2 * _leg_for(d) + 2 * np.pi * U_RADIUS),
    ZIGZAG: Course(_zigzag, 0.0, lambda d: 2 * ZIG),
    SQUARE: Course(_square, 2 * np.pi, lambda d: 4 * float(np.clip(d / 4, SIDE_MIN, SIDE_MAX))),
    DIAGONAL: Course(_veer(DIAGONAL_ANGLE, DIAGONAL_EASE), DIAGONAL_ANGLE, lambda d: 2 * d + 10.0),
    ASIDE: Course(_veer(ASIDE_ANGLE, ASIDE_EASE), ASIDE_ANGLE, lambda d: 2 * d + 10.0),
}


def course_seconds(course: str, speed: float) -> float | None:
    """The length (s) a motion with no length asked gets to walk ``course`` once round at ``speed``
    m/s (its gait's typical pace): the course's shortest period over ``UNASKED_PACE`` of that speed
    (a slower sample still gets round), within ``UNASKED_LEAST`` .. ``UNASKED_MOST``; None for a
    course with no round (a diagonal, a gait to one side)."""
    if course in (DIAGONAL, ASIDE) or course not in COURSES or speed <= 0:
        return None
    period = COURSES[course].period_for(0.0)
    return float(np.clip(period / (UNASKED_PACE * speed), UNASKED_LEAST, UNASKED_MOST))


ROUND = {CIRCLE: "circle", EIGHT: "figure eight", BACK_AND_FORTH: "way out and back", SQUARE: "square"}   # gone round
NOTE_BELOW = 0.9   # a course gone round less than this share of once is noted


def unasked_seconds(words, speeds: dict[str, float]) -> float | None:
    """The length the way the words (``plan.words.Words``) name gets when none is asked: a course
    once round (``course_seconds``), or a distance ("walks 5 metres, then turns around") gone at
    ``UNASKED_PACE`` of the pace and then ``STOP_SECONDS`` standing (at most ``UNASKED_MOST``); at
    the typical pace ``speeds`` (``typical_pace.load_typical_speeds``) of its gait (walk, jog or
    run; a walk's for another gait, ``WALK_SPEED`` without a table), slowed when asked slowly. None
    for no course and no distance, or a course with no round."""
    from .pace_words import SLOW_SPEED

    if words.course is None and words.distance_m is None:
        return None
    if words.course is not None:
        gait = words.course_gait[1] if words.course_gait else None
    else:
        gait = next((a for a in words.actions if a in speeds), None)
    speed = (speeds.get(gait) or speeds.get("walk") or WALK_SPEED) * (SLOW_SPEED if words.pace == "slow" else 1.0)
    if words.course is None:
        return float(min(words.distance_m / (UNASKED_PACE * speed) + STOP_SECONDS, UNASKED_MOST))
    return course_seconds(words.course, speed)


def model_course_seconds(model_dir=None):
    """``unasked_seconds`` at the typical pace of the model folder ``model_dir`` (None: the default
    model), as ``plan.Plan.lengths`` takes it: what ``--explain`` and the panel show without loading
    the model. A folder that is missing or has no usable table gives a walk's ``WALK_SPEED`` (a plan
    needs no model; generating names the folder's problem)."""
    from ..errors import ShapeMoveError
    from .model_bundle import resolve_model_dir
    from .typical_pace import load_typical_speeds

    try:
        speeds = load_typical_speeds(resolve_model_dir(model_dir))
    except ShapeMoveError:
        speeds = {}
    return lambda words: unasked_seconds(words, speeds)


def round_share(course: str | None, distance: float) -> float | None:
    """The share of once round ``course`` a motion that travels ``distance`` metres goes (its
    period at that distance: a circle's radius is at least ``MIN_RADIUS``); None for a course with
    no round (a zigzag, a diagonal, a gait to one side)."""
    if course not in ROUND or distance <= 0:
        return None
    return float(distance / COURSES[course].period_for(distance))


def whole_period(course: str, distance: float) -> float:
    """The period (m) of ``course`` fitted to ``distance`` a whole number of times (at least once)."""
    return distance / max(1, round(distance / COURSES[course].period_for(distance)))
