"""What the word readers understand of one segment's text, as a plain dict for people and JSON.

    understood("a man walks 3 metres forward and stops")
    -> {"actions": ["walk"], "travel": "forward", "distance_m": 3.0, "stop": True}

Each entry is the reading the generator acts on, by the reader that acts on it: the course
(``course_walk.course_named``), a named turn (``turn_words.angle_of``), a distance, counted steps
and a stop (``stop_words``), a counted jump or squat (``count_words.asked_count``), a gait kept in
place (``on_the_spot``), the travel (``travel_words``), a fast or slow pace (``pace_words``), a named
side (``part_prompts.named_side``), two things at once (``part_prompts.plan_parts``). Readings that
are absent are left out.
"""
from __future__ import annotations

import math

from ..data.actions import find_actions
from ..generation.count_words import asked_count
from ..generation.course_walk import course_named, turns_right
from ..generation.on_the_spot import asks_on_the_spot
from ..generation.pace_words import asks_fast, asks_slow_flight, asks_slow_steps
from ..generation.part_prompts import named_side, plan_parts
from ..generation.stop_words import asked_distance, asks_stand_still, stop_request
from ..generation.travel_words import travel_of
from ..generation.turn_words import angle_of


def understood(text: str) -> dict:
    """The readings of ``text`` (module doc): only what the words ask."""
    low = str(text).lower()
    out: dict = {}
    actions = find_actions(low)
    if actions:
        out["actions"] = actions
    parts = plan_parts(low)
    if parts is not None:
        out["legs"], out["arms"] = parts.legs_prompt, parts.arms_prompt
    course = course_named(low)
    if course is not None:
        out["course"] = course
        out["course_way"] = "right" if turns_right(low) else "left"
    angle = angle_of(low)
    if angle is not None:
        out["turn_degrees"] = round(math.degrees(angle))
    go = travel_of(low)
    way = {1: "forward", -1: "backward"}.get(go.forward) or {1: "left", -1: "right"}.get(go.side) or (
        "sideways" if go.sideways else None)
    if way is not None:
        out["travel"] = way
    if asks_on_the_spot(low):
        out["in_place"] = True
    stop = stop_request(low)
    if stop is not None:
        metres = asked_distance(low)
        if metres is not None:
            out["distance_m"] = round(metres, 2)
        if stop[1] is not None:
            out["steps"] = stop[1]
        out["stop"] = True
    elif asks_stand_still(low):
        out["stand_still"] = True
    count = asked_count(low)
    if count is not None:
        out["count"] = count[1]
    if asks_fast(low):
        out["pace"] = "fast"
    elif asks_slow_steps(low) or asks_slow_flight(low):
        out["pace"] = "slow"
    side = named_side(low)
    if side is not None:
        out["side"] = f"{side[0]} {side[1]}"
    return out


def said(reading: dict) -> str:
    """One line of a reading for people: "walk; forward; 3 m, then stands"."""
    bits = []
    if "legs" in reading:
        bits.append(f"legs {reading['legs']!r} + arms {reading['arms']!r}")
    elif reading.get("actions"):
        bits.append(", ".join(reading["actions"]))
    if "course" in reading:
        bits.append(f"course: {reading['course']} (to the {reading['course_way']})")
    if "turn_degrees" in reading:
        bits.append(f"turn {reading['turn_degrees']} degrees")
    if "travel" in reading:
        bits.append(reading["travel"])
    if reading.get("in_place"):
        bits.append("in place")
    if "distance_m" in reading:
        bits.append(f"{reading['distance_m']:g} m")
    if "steps" in reading:
        bits.append(f"{reading['steps']} steps")
    if reading.get("stop"):
        bits.append("then stands")
    if reading.get("stand_still"):
        bits.append("stands still")
    if "count" in reading:
        bits.append(f"{reading['count']} times")
    if "pace" in reading:
        bits.append(reading["pace"])
    if "side" in reading:
        bits.append(f"side: {reading['side']}")
    return "; ".join(bits) if bits else "no word the readers act on (the model reads the prompt whole)"
