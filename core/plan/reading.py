"""What was understood of one segment's text, as a plain dict for people and JSON.

    understood("a man walks 3 metres forward and stops")
    -> {"actions": ["walk"], "travel": "forward", "distance_m": 3.0, "stop": True}

The dict is ``words.Words.understood`` of ``words.read_words``: the reading the generator acts on
(the actions, two things at once, the course and its way round, a turn, the travel, a gait kept
in place, a distance, counted steps and a stop, standing still, a count, a pace, a length, a named
side, and the words no class took). Readings that are absent are left out.
"""
from __future__ import annotations

from .vocabulary import ASIDE_COURSE, COURSE_NAMES
from .words import read_words


def understood(text: str) -> dict:
    """The readings of ``text`` (module doc): only what the words ask."""
    return read_words(str(text)).understood()


def course_said(reading: dict) -> str:
    """A reading's course as people say it: "in a circle", "zigzag", "to the left" (a gait to one side)."""
    if reading["course"] == ASIDE_COURSE:
        return f"to the {reading.get('course_way', 'left')}"
    return COURSE_NAMES.get(reading["course"], reading["course"])


def said(reading: dict) -> str:
    """One line of a reading for people: "walk; forward; 3 m, then stands"."""
    bits = []
    if "legs" in reading:
        bits.append(f"legs {reading['legs']!r} + arms {reading['arms']!r}")
    elif reading.get("actions"):
        bits.append(", ".join(reading["actions"]))
    if "course" in reading and reading["course"] == ASIDE_COURSE:
        bits.append(f"course: {course_said(reading)}, a quarter turn")
    elif "course" in reading:
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
    if reading.get("slowly"):
        bits.append("slowly")
    if "seconds" in reading:
        bits.append(f"for {reading['seconds']:g} s")
    if "side" in reading:
        bits.append(f"side: {reading['side']}")
    if reading.get("arms_held"):
        bits.append("arms held raised")
    if reading.get("held_low"):
        bits.append("held at its lowest")
    if reading.get("hands"):
        bits.append("both hands" if reading["hands"] == "both" else "one hand")
    if reading.get("one_foot"):
        bits.append("on one foot")
    if reading.get("again"):
        bits.append("again and again")
    if reading.get("manner"):
        bits.append(f"manner: {reading['manner']}")
    said = "; ".join(bits) if bits else "no word the readers act on (the model reads the prompt whole)"
    if reading.get("unused"):   # named, never dropped in silence
        said += "; not used: " + ", ".join(repr(w) for w in reading["unused"])
    return said
