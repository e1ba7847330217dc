"""Shape texts in the words people use for a body: man or woman, age, build, weight, height.

``phenotype_texts(phenotype, measures, key)`` describes a body from its OpenBody phenotype sliders
(gender 0 = male .. 1 = female, age in years, muscle 0..1, weight 0..1, ...) and its measurements
(height in cm, and mass in kg when ``measure`` gives it) in several forms: nouns chosen by gender
and age ("a man", "a teenage girl", "a grandmother"), build and size words ("muscular",
"overweight", "slim", "tall", "petite"), ages ("a 72-year-old woman", "in his thirties") and
numbers in the units people type ("188 cm", "6 ft 2", "92 kg", "200 lb"). The `[BETA]` head learns
from these (the shape augmentation's bodies are drawn from phenotypes: ``body/phenotype_sample``),
so that free text the parser does not cover ("a lanky teenage boy", "a powerlifter") still lands
on a body of the right kind. Deterministic for a ``key``.
"""
from __future__ import annotations

import random

MALE, FEMALE = 0.25, 0.75   # gender slider: <= MALE a man's body, >= FEMALE a woman's


def _nouns(g: float, age: float) -> tuple[list[str], str, str]:
    """(noun phrases without article, subject pronoun, possessive) for a gender and age."""
    if g <= MALE:
        if age < 20:
            return ["boy", "teenage boy", "teenager", "young lad"], "he", "his"
        if age >= 65:
            return ["old man", "elderly man", "grandfather", "grandpa", "senior man"], "he", "his"
        return ["man", "guy", "male", "gentleman"], "he", "his"
    if g >= FEMALE:
        if age < 20:
            return ["girl", "teenage girl", "teenager", "young lass"], "she", "her"
        if age >= 65:
            return ["old woman", "elderly woman", "grandmother", "granny", "old lady", "senior woman"], "she", "her"
        return ["woman", "lady", "female", "gal"], "she", "her"
    if age >= 65:
        return ["elderly person", "senior"], "they", "their"
    return ["person", "adult"], "they", "their"


def age_words(age: float) -> list[str]:
    if age < 20:
        return ["teenage", "adolescent"]
    if age <= 30:
        return ["young", "youthful"]
    if 40 <= age < 60:
        return ["middle-aged"]
    if age >= 65:
        return ["elderly", "old", "aged"]
    return []


def decade_words(age: float) -> str:
    """"teens", "twenties", ... "eighties" for an age in years (as in "a woman in her seventies")."""
    names = {10: "teens", 20: "twenties", 30: "thirties", 40: "forties", 50: "fifties", 60: "sixties",
             70: "seventies", 80: "eighties"}
    return names.get(int(age // 10) * 10, "teens" if age < 20 else "eighties" if age >= 80 else "forties")


def _build_words(muscle: float, weight: float, height_cm: float | None, g: float) -> list[str]:
    out = []
    lean_only = muscle >= 0.6  # a muscular body is "lean", never "skinny" or "scrawny"
    if muscle >= 0.75:
        out += ["muscular", "ripped", "very muscular", "brawny", "bodybuilder-like"]
    elif muscle >= 0.6:
        out += ["athletic", "fit", "toned", "sporty"]
    elif muscle <= 0.15:
        out += ["untoned"]
    if weight >= 0.85:
        out += ["obese", "very heavy", "very overweight"]
    elif weight >= 0.68:
        out += ["overweight", "heavy-set", "chubby", "stocky", "plump", "heavy"]
    elif weight <= 0.15 and not lean_only:
        out += ["skinny", "very thin", "scrawny"]
    elif weight <= 0.15:
        out += ["lean", "slim"]
    elif weight <= 0.32:
        out += ["slim", "thin", "slender", "lean"]
    if height_cm is not None:
        if height_cm >= 195:
            out += ["very tall", "towering"]
        elif height_cm >= 184:
            out += ["tall"] + (["lanky"] if weight <= 0.35 else [])
        elif height_cm <= 152:
            out += ["very short", "tiny"]
        elif height_cm <= 162:
            out += ["short"] + (["petite"] if g >= FEMALE and weight <= 0.5 else [])
    return out


def _height(cm: float, rng: random.Random) -> str:
    inches = round(cm / 2.54)
    ft, inch = divmod(inches, 12)
    return rng.choice([f"{cm:.0f} cm", f"{cm / 100:.2f} m", f"{ft} ft {inch}", f"{ft}'{inch}\""])


def _mass(kg: float, rng: random.Random) -> str:
    return rng.choice([f"{kg:.0f} kg", f"{kg * 2.20462:.0f} lb", f"{kg:.0f} kilos"])


def _has_age(noun: str) -> bool:
    return any(w in noun for w in ("old", "elderly", "senior", "teen", "young", "grand", "boy", "girl", "lad", "lass"))


def _article(word: str) -> str:
    return "an" if word[:1].lower() in "aeiou" else "a"


def phenotype_texts(phenotype: dict, measures: dict | None, key: str, n: int = 4) -> list[str]:
    """``n`` descriptions of a body with ``phenotype`` (slider name -> value) and ``measures``
    (``body.measure`` names: height_cm, and mass_kg when available)."""
    rng = random.Random(f"phenotype/{key}")
    g, age = float(phenotype.get("gender", 0.5)), float(int(phenotype.get("age", 40.0)))  # whole years, as people say
    muscle, weight = float(phenotype.get("muscle", 0.4)), float(phenotype.get("weight", 0.5))
    measures = measures or {}
    h = measures.get("height_cm")
    kg = measures.get("mass_kg")
    nouns, pron, poss = _nouns(g, age)
    ages, builds = age_words(age), _build_words(muscle, weight, h, g)
    out = []
    for _ in range(n * 3):
        noun = rng.choice(nouns)
        kind = rng.randrange(7)
        adjs = rng.sample(builds, min(len(builds), rng.randrange(1, 3))) if builds else []
        if kind == 0 or (kind in (3, 4) and h is None):                        # "a tall muscular man"
            words = adjs + ([rng.choice(ages)] if ages and rng.random() < 0.6 and not _has_age(noun) else [])
            phrase = " ".join(words + [noun])
            s = f"{_article(phrase)} {phrase}"
        elif kind == 1:                                                        # "a 72-year-old woman, slim"
            s = f"a {age:.0f}-year-old {noun}" + (f", {rng.choice(builds)}" if builds else "")
        elif kind == 2:                                                        # "a woman in her seventies"
            phrase = " ".join(adjs[:1] + [noun])
            s = f"{_article(phrase)} {phrase} in {poss} {decade_words(age)}"
        elif kind == 3:                                                        # "a man, 188 cm, 92 kg"
            parts = [_height(h, rng)] + ([_mass(kg, rng)] if kg else [])
            s = f"{_article(noun)} {noun}, " + ", ".join(parts)
        elif kind == 4 and kg:                                                 # "she weighs 61 kg"
            s = f"{_article(noun)} {noun} who weighs {_mass(kg, rng)}" + (f" and is {_height(h, rng)} tall"
                                                                          if rng.random() < 0.5 else "")
        elif kind == 5:                                                        # "he is muscular and tall"
            s = f"{pron} is " + (" and ".join(adjs) if adjs else f"{_article(noun)} {noun}")
        else:                                                                  # "an athletic young woman"
            words = ([rng.choice(builds)] if builds else []) + ([rng.choice(ages)] if ages and not _has_age(noun) else [])
            phrase = " ".join(words + [noun])
            s = f"{_article(phrase)} {phrase}"
        s = s[0].upper() + s[1:] + "."
        if s not in out:
            out.append(s)
        if len(out) == n:
            break
    return out
