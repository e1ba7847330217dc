"""The typed reading of one segment's words: what every downstream module acts on.

    w = read_words("a man walks 3 metres forward and stops")
    w.actions, w.travel.way, w.distance_m, w.stop   -> ("walk",), "forward", 3.0, True
    w.gait_text                                     -> "a man walks forward" (what the gait is sampled from)
    w.understood()                                  -> {"actions": ["walk"], "travel": "forward", "distance_m": 3.0, "stop": True}

``read_words`` is the one place the vocabulary (``vocabulary.py``) is matched against a text
(``reader.py`` reads each class); a reading is read once per text and kept (``lru_cache``).
A plan edited by the user (``plan.plan_from_json``) replaces the fields of a reading with
``dataclasses.replace``; the generator acts on the fields, never on the text again.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

from ..data.actions import find_actions
from . import reader as R
from .part_prompts import PartPlan, named_side, plan_parts
from . import vocabulary as V
from .vocabulary import COURSE_ACTIONS


@dataclass(frozen=True)
class Words:
    """What the words of one text ask (each field None / False / empty when they ask nothing of it)."""
    text: str
    actions: tuple[str, ...] = ()
    parts: PartPlan | None = None              # two things at once: the legs and arms prompts
    side: tuple[str, str] | None = None        # ("left" | "right", "hand" | "foot") of a single action
    course: str | None = None                  # ``vocabulary.CIRCLE`` ... ``DIAGONAL_COURSE``
    course_right: bool = False                 # clockwise seen from above
    turn: float | None = None                  # radians, + = left
    travel: R.Travel = field(default_factory=R.Travel)
    in_place: bool = False                     # a gait kept on the spot
    stop: bool = False                         # the gait stops (after ``steps``, at ``distance_m``, or halfway)
    steps: int | None = None
    distance_m: float | None = None
    gait_text: str | None = None               # the words without their stop clause or distance (a stop's gait)
    stand_still: bool = False                  # only standing still ("waits", "stands still")
    count: tuple[str, int] | None = None       # (countable action, times)
    pace: str | None = None                    # "fast" | "slow"
    slow_flight: bool = False                  # slow of a gait with flights (a jog, a run): shorter strides
    slowly: bool = False                       # an action that is no gait done slowly ("sits down slowly")
    gestures_only: bool = False                # every action named is an arms action ("he waves")
    arms_held: bool = False                    # the arms kept raised ("with both arms raised")
    held_low: bool = False                     # a squat kept down ("squats and holds it")
    hands: str | None = None                   # a gesture's hands: "both" ("waves with both hands"), "one" ("a hand")
    one_foot: bool = False                     # a hop or a jump on one foot (no capture does one)
    again: bool = False                        # a counted action again and again, no number ("squats repeatedly")
    seconds: float | None = None               # the length the words ask ("for ten seconds")
    manner: str | None = None                  # how it is done (``vocabulary.MANNERS``: "proud")
    unused: tuple[str, ...] = ()               # words no class took ("impatiently")

    @property
    def slow_steps(self) -> bool:
        """Slow of a stepping gait (a walk, a march): played slower."""
        return self.pace == "slow" and not self.slow_flight

    @property
    def course_gait(self) -> tuple[str, str] | None:
        """(the words without the course, the gait left in them) of a course (``reader.straight_gait``)."""
        return R.straight_gait(self.text) if self.course is not None else None

    @property
    def straight_text(self) -> str:
        """The words a course's gait is sampled from, else the text itself (``reader.walked_straight``)."""
        gait = self.course_gait
        return gait[0] if gait else self.text

    def understood(self) -> dict:
        """The reading as a plain dict for people and JSON: only what the words ask."""
        out: dict = {}
        if self.actions:
            out["actions"] = list(self.actions)
        if self.parts is not None:
            out["legs"], out["arms"] = self.parts.legs_prompt, self.parts.arms_prompt
        if self.course is not None:
            out["course"] = self.course
            out["course_way"] = "right" if self.course_right else "left"
        if self.turn is not None:
            out["turn_degrees"] = round(math.degrees(self.turn))
        if self.travel.way is not None:
            out["travel"] = self.travel.way
        if self.in_place or self.travel.in_place:   # a gait on the spot, or a jump that stays
            out["in_place"] = True
        if self.stop:
            if self.distance_m is not None:
                out["distance_m"] = round(self.distance_m, 2)
            if self.steps is not None:
                out["steps"] = self.steps
            out["stop"] = True
        elif self.stand_still:
            out["stand_still"] = True
        if self.count is not None:
            out["count"] = self.count[1]
        if self.pace is not None:
            out["pace"] = self.pace
        if self.slowly:
            out["slowly"] = True
        if self.side is not None:
            out["side"] = f"{self.side[0]} {self.side[1]}"
        if self.arms_held:
            out["arms_held"] = True
        if self.held_low:
            out["held_low"] = True
        if self.hands is not None:
            out["hands"] = self.hands
        if self.one_foot:
            out["one_foot"] = True
        if self.again:
            out["again"] = True
        if self.seconds is not None:
            out["seconds"] = self.seconds
        if self.manner is not None:
            out["manner"] = self.manner
        if self.unused:
            out["unused"] = list(self.unused)
        return out


@lru_cache(maxsize=4096)
def read_words(text: str) -> Words:
    """The typed reading of ``text`` (module doc)."""
    low = str(text).lower()
    stop = R.stop_request(low)
    metres = R.asked_distance(low) if stop is not None else None
    course = R.course_named(low)
    pace = "fast" if R.asks_fast(low) else "slow" if (R.asks_slow_steps(low) or R.asks_slow_flight(low)) else None
    slowly = pace is None and R.asks_slow_action(low)
    again = R.again(low)
    if stop is not None:   # the words without the stop, in the prompt's own case
        stop = R.stop_request(str(text))
    return Words(
        text=str(text), actions=tuple(find_actions(low)), parts=plan_parts(low), side=named_side(low),
        course=course, course_right=course is not None and R.turns_right(low), turn=R.angle_of(low),
        travel=R.travel_of(low), in_place=R.asks_on_the_spot(low), stop=stop is not None,
        steps=None if stop is None else stop[1], distance_m=None if metres is None else float(metres),
        gait_text=None if stop is None else stop[0],
        stand_still=stop is None and R.asks_stand_still(low), count=R.asked_count(low), pace=pace,
        slow_flight=pace == "slow" and R.asks_slow_flight(low), slowly=slowly, gestures_only=R.gestures_only(low),
        arms_held=R.arms_held(low), held_low=R.held_low(low), hands=R.hands_asked(low), one_foot=R.one_foot(low), again=again,
        seconds=R.asked_seconds(low),
        manner=R.manner_of(low),
        unused=tuple(R.unused_words(low, _body_words(low), (() if pace or slowly else (V.FAST, V.SLOW))
                                    + (() if again else (V.AGAIN,)))))


def _body_words(low: str) -> list[str]:
    """The words that describe the body ("old", "tall", "heavy"): read by the body's reader."""
    from ..errors import ShapeMoveError
    from ..text.shape_words import parse_shape_words

    try:
        said = parse_shape_words(R.without_numbers(low))
    except ShapeMoveError:
        return []
    return [w for bit in list(said.words) + list(said.build_words) + list(said.size_words) for w in str(bit).split()]


def with_fields(words: Words, **changes) -> Words:
    """``words`` with some fields changed (an edited plan): the generator acts on the fields."""
    return replace(words, **changes)


def is_course_action(action: str | None) -> bool:
    """Whether an action of the data is a course (a circle, a figure eight)."""
    return action in COURSE_ACTIONS
