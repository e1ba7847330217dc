"""Body-shape texts from mesh measurements: the shape augmentation of the [BETA] head.

Input everywhere: the dict of ``core.body.measure.measure`` (height_cm, chest_cm, waist_cm,
hip_cm, arm_length_cm, leg_length_cm).

- ``shape_sentence``: the paper's long numeric form ("A person standing 182 cm tall, with a chest
  circumference of 101 cm, ...");
- ``numeric_shape_text``: short numeric forms in cm, m or feet/inches ("1.82 m tall, waist 100 cm",
  "6 ft 0 in tall with a 39-inch waist");
- ``shape_adjectives`` / ``adjective_shape_text``: size words ("a tall, heavy-set man", "a
  lanky person", "petite", "stocky");
- ``mix_into_prompt``: the shape inside the motion prompt ("A tall, heavy-set man jogs.");
- ``shape_texts``: the set the dataset builder writes per clip (first line: the long sentence);
- ``parse_shape_text``: the numbers a text states (all the numeric forms above), in cm: THE parser
  is ``core/text/shape_words.py`` (re-exported here for the builder's users).

THE size-word table is ``ADJECTIVES`` (defined in ``text/shape_words.py``, the parser's vocabulary):
for each word the range of height (cm) and of waist-to-
height ratio (WHtR, waist = WHtR x height) of the bodies it is written for. The generator only
writes a word for a body inside its ranges (tests check it), so a model trained on these texts can
be tested against them: "tall" -> 180-190 cm, "slim" -> waist < 0.43 x height, and so on.
Height bands follow common usage for adults; the build bands are the usual WHtR bands (< 0.43
slim, 0.43-0.53 average, > 0.53 heavy, > 0.60 very heavy), which the shape space spans
(OpenBody with betas ~ N(0,1): height 143-192 cm, WHtR 0.32-0.63, 1st-99th percentiles).
"""
from __future__ import annotations

import hashlib
import re

from ..text.shape_words import ADJECTIVES, H_MAX, H_MIN, R_MAX, R_MIN, parse_shape_text

NOUNS = {"male": "man", "female": "woman", None: "person"}

HEIGHT_WORDS = ["very short", "short", "of average height", "tall", "very tall"]
BUILD_WORDS = {"slim": ["slim", "slender", "thin"], "of average build": ["of average build"],
               "heavy-set": ["heavy-set", "heavy"], "very heavy": ["very heavy"]}


def in_range(word: str, height_cm: float, waist_cm: float) -> bool:
    """Whether a body of this height and waist lies in the word's ranges (``ADJECTIVES``)."""
    h_rng, r_rng = ADJECTIVES[word]
    r = waist_cm / max(height_cm, 1.0)
    return (h_rng is None or h_rng[0] <= height_cm < h_rng[1]) and (r_rng is None or r_rng[0] <= r < r_rng[1])


def word_targets(word: str, height_cm: float | None = None) -> dict:
    """The middle of a word's ranges as target measurements: {"height_cm"?, "waist_cm"?} (the waist
    at ``height_cm``, else at the band's middle height, else omitted when no height is known)."""
    h_rng, r_rng = ADJECTIVES[word]
    out = {}
    if h_rng is not None:
        lo, hi = max(h_rng[0], 145.0), min(h_rng[1], 200.0)
        out["height_cm"] = (lo + hi) / 2
    h = out.get("height_cm", height_cm)
    if r_rng is not None and h is not None:
        lo, hi = max(r_rng[0], 0.33), min(r_rng[1], 0.66)
        out["waist_cm"] = (lo + hi) / 2 * h
    return out


def _band(words: list[str], height_cm: float, waist_cm: float) -> str:
    return next(w for w in words if in_range(w, height_cm, waist_cm))


def height_word(height_cm: float) -> str | None:
    """The height band's word, None for average height."""
    w = _band(HEIGHT_WORDS, min(max(height_cm, H_MIN), H_MAX - 1e-6), 0.0 + 0.48 * height_cm)
    return None if w == "of average height" else w


def build_word(waist_cm: float, height_cm: float) -> str | None:
    """The build band's word by waist-to-height ratio, None for an average build."""
    r = min(max(waist_cm / max(height_cm, 1.0), R_MIN), R_MAX - 1e-6)
    w = _band(list(BUILD_WORDS), 100.0, 100.0 * r)  # the ratio alone decides
    return None if w == "of average build" else w


def shape_sentence(m: dict, gender: str | None = None) -> str:
    who = {"male": "A male", "female": "A female"}.get(gender, "A person")
    return (
        f"{who} standing {m['height_cm']:.0f} cm tall, with a chest circumference of {m['chest_cm']:.0f} cm, "
        f"a waist circumference of {m['waist_cm']:.0f} cm, a hip circumference of {m['hip_cm']:.0f} cm, "
        f"an arm length of {m['arm_length_cm']:.0f} cm and a leg length of {m['leg_length_cm']:.0f} cm."
    )


def _article(phrase: str) -> str:
    return "an" if phrase[:1] in "aeiou" else "a"


def shape_adjectives(m: dict, gender: str | None = None) -> str:
    """The plain adjective form: "a tall, heavy-set man", "an average-sized person"."""
    words = [w for w in (height_word(m["height_cm"]), build_word(m["waist_cm"], m["height_cm"])) if w]
    if not words:
        words = ["average-sized"]
    phrase = ", ".join(words)
    return f"{_article(phrase)} {phrase} {NOUNS.get(gender, 'person')}"


def size_words(m: dict) -> list[list[str]]:
    """Every word list that describes this body (each word inside its ``ADJECTIVES`` ranges):
    [height word, build synonym] pairs, the single words that cover both (petite, lanky, stocky,
    big, average-sized), "of average height/build" beside the other band's word, and a height or
    build word alone."""
    h, w = m["height_cm"], m["waist_cm"]
    hw = height_word(h)
    bw = build_word(w, h)
    out: list[list[str]] = []
    for word in ("petite", "lanky", "stocky", "big", "average-sized"):
        if in_range(word, h, w):
            out.append([word])
    builds = BUILD_WORDS[bw] if bw else []
    if hw and builds:
        out += [[hw, b] for b in builds]
    elif builds:                                   # "a slim person of average height"
        out += [[builds[0], "of average height"]]
    elif hw:                                       # "a tall person of average build"
        out += [[hw, "of average build"]]
    out += [[hw]] if hw else []
    out += [[b] for b in builds]
    return out or [["average-sized"]]


def _seed(key: str) -> int:
    return int(hashlib.sha1(key.encode()).hexdigest()[:8], 16)


def _choose(key: str, options: list):
    return options[_seed(key) % len(options)]


def adjective_shape_text(m: dict, key: str) -> str:
    """A size-word shape text for this body, chosen by ``key`` (deterministic): "a lanky woman",
    "tall and slim", "a short, heavy-set person", "someone who is very tall"."""
    words = _choose(key + "/w", size_words(m))
    noun = _choose(key + "/n", ["person", "person", "man", "woman"])
    joined_comma = ", ".join(words)
    joined_and = " and ".join(words)
    forms = [f"{_article(joined_comma)} {joined_comma} {noun}", f"{joined_and}",
             f"someone who is {joined_and}", f"the person is {joined_and}"]
    if any(w.startswith("of ") for w in words):  # "of average height" is no pre-noun adjective
        forms = [f"a {noun} {joined_and}" if words[0].startswith("of ") else f"{_article(words[0])} {words[0]} {noun} "
                 f"{' and '.join(words[1:])}", f"someone who is {joined_and}", f"the person is {joined_and}"]
    return _choose(key + "/f", forms).strip()


def feet_inches(cm: float) -> tuple[int, int]:
    inches = int(round(cm / 2.54))
    return inches // 12, inches % 12


def numeric_shape_text(m: dict, key: str) -> str:
    """A short numeric shape text (height and waist) in one of several unit styles, chosen by
    ``key``: cm, metres (2 decimals) or feet/inches with the waist in inches."""
    h, w = m["height_cm"], m["waist_cm"]
    ft, inch = feet_inches(h)
    w_in = w / 2.54
    forms = [
        f"{h / 100:.2f} m tall, waist {w:.0f} cm",
        f"{h:.0f} cm tall with a {w:.0f} cm waist",
        f"height {h:.0f} cm, waist {w:.0f} cm",
        f"a person {h:.0f} cm tall, waist circumference {w:.0f} cm",
        f"{ft} ft {inch} in tall, waist {w_in:.0f} inches",
        f"{ft}'{inch}\" tall with a {w_in:.0f}-inch waist",
        f"someone {h / 100:.2f} m tall with a waist of {w:.0f} cm",
    ]
    return _choose(key + "/num", forms)


_SUBJECT = re.compile(r"^(a person|someone|the person|a man|a woman|a human)\b\s*", re.IGNORECASE)


def mix_into_prompt(caption: str, m: dict, key: str, numeric: bool = False) -> str | None:
    """The body's shape inside a motion caption: "A person jogs." -> "A tall, heavy-set man jogs."
    (or, ``numeric``, "A person, 1.86 m tall with a 99 cm waist, jogs."). None when the caption
    does not start with a plain subject ("a person", "someone", ...)."""
    mt = _SUBJECT.match(caption.strip())
    if not mt:
        return None
    rest = caption.strip()[mt.end():]
    if numeric:
        h, w = m["height_cm"], m["waist_cm"]
        ft, inch = feet_inches(h)
        desc = _choose(key + "/mixnum", [f"{h / 100:.2f} m tall with a {w:.0f} cm waist",
                                         f"{h:.0f} cm tall with a waist of {w:.0f} cm",
                                         f"{ft} ft {inch} in tall with a {w / 2.54:.0f}-inch waist"])
        subj = f"{mt.group(1).lower()}, {desc},"
    else:
        words = [x for x in _choose(key + "/mixw", size_words(m)) if not x.startswith("of ")] or ["average-sized"]
        noun = _choose(key + "/mixn", ["person", "man", "woman"])
        phrase = _choose(key + "/mixj", [", ".join(words), " ".join(words)])
        subj = f"{_article(phrase)} {phrase} {noun}"
    text = f"{subj} {rest}"
    return text[0].upper() + text[1:]


def shape_texts(m: dict, key: str) -> list[str]:
    """The shape texts the builder writes for a clip (``key``: its id): the long numeric sentence
    first (evaluation reads it), then the plain adjectives, a short numeric form, another size-word
    form and a feet/inches or metres form."""
    out = [shape_sentence(m), shape_adjectives(m), numeric_shape_text(m, key), adjective_shape_text(m, key),
           numeric_shape_text(m, key + "/2"), adjective_shape_text(m, key + "/2")]
    return list(dict.fromkeys(out))


def parse_shape_sentence(text: str) -> dict:
    """The measurements a numeric shape text states (kept name; see ``parse_shape_text``)."""
    return parse_shape_text(text)
