"""Body-shape sentences in the style of the paper's shape texts, from mesh measurements.

``shape_sentence`` gives the long, numeric form ("A person standing 182 cm tall, with a chest
circumference of 101 cm, ..."); ``shape_adjectives`` the short form ("a tall, heavy-set person").
Input: the dict of ``core.body.measure.measure`` (height_cm, chest_cm, waist_cm, hip_cm,
arm_length_cm, leg_length_cm).
"""
from __future__ import annotations

import re

NOUNS = {"male": "man", "female": "woman", None: "person"}


def shape_sentence(m: dict, gender: str | None = None) -> str:
    who = {"male": "A male", "female": "A female"}.get(gender, "A person")
    return (
        f"{who} standing {m['height_cm']:.0f} cm tall, with a chest circumference of {m['chest_cm']:.0f} cm, "
        f"a waist circumference of {m['waist_cm']:.0f} cm, a hip circumference of {m['hip_cm']:.0f} cm, "
        f"an arm length of {m['arm_length_cm']:.0f} cm and a leg length of {m['leg_length_cm']:.0f} cm."
    )


def height_word(height_cm: float) -> str | None:
    if height_cm < 155:
        return "very short"
    if height_cm < 165:
        return "short"
    if height_cm >= 190:
        return "very tall"
    if height_cm >= 180:
        return "tall"
    return None


def build_word(waist_cm: float, height_cm: float) -> str | None:
    """Waist-to-height ratio: < 0.43 slim, > 0.53 heavy-set, > 0.60 obese (common WHtR bands)."""
    r = waist_cm / max(height_cm, 1.0)
    if r < 0.43:
        return "slim"
    if r > 0.60:
        return "very heavy"
    if r > 0.53:
        return "heavy-set"
    return None


def shape_adjectives(m: dict, gender: str | None = None) -> str:
    words = [w for w in (height_word(m["height_cm"]), build_word(m["waist_cm"], m["height_cm"])) if w]
    if not words:
        words = ["average-sized"]
    noun = NOUNS.get(gender, "person")
    phrase = ", ".join(words)
    article = "an" if phrase[0] in "aeiou" else "a"
    return f"{article} {phrase} {noun}"


_NUMBER_FIELDS = {
    "height_cm": r"(\d+(?:\.\d+)?)\s*cm tall|height of (\d+(?:\.\d+)?)\s*cm",
    "chest_cm": r"chest circumference of (\d+(?:\.\d+)?)",
    "waist_cm": r"waist circumference of (\d+(?:\.\d+)?)",
    "hip_cm": r"hip circumference of (\d+(?:\.\d+)?)",
    "arm_length_cm": r"arm length of (\d+(?:\.\d+)?)",
    "leg_length_cm": r"leg length of (\d+(?:\.\d+)?)",
}


def parse_shape_sentence(text: str) -> dict:
    """The measurements a numeric shape text states (only those present)."""
    out = {}
    for key, pattern in _NUMBER_FIELDS.items():
        mt = re.search(pattern, text, flags=re.IGNORECASE)
        if mt:
            out[key] = float(next(g for g in mt.groups() if g))
    return out
