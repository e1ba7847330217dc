"""Shape words and numbers: THE reader of what a shape text says about a body.

    d = parse_shape_words("a muscular 188 cm man, 92 kg")
    d.gender, d.muscle, d.height_cm, d.mass_kg        # 0.0, 0.85, 188.0, 92.0

It reads
- gender: nouns and pronouns ("man", "woman", "boy", "girl", "guy", "lady", "grandmother", "he",
  "she", ...) -> OpenBody's gender slider, 0 = male .. 1 = female;
- age: numbers ("35 years old", "a 35-year-old", "aged 35", "in her 60s", "in his early
  twenties") and words ("elderly", "old", "middle-aged", "young", "teenage", ...), in years; nouns
  that imply an age ("girl", "grandfather") give a default when nothing else states one;
- build: muscle words ("muscular", "athletic", "fit", "ripped", strength sports: "bodybuilder",
  "powerlifter", ...) and weight words ("skinny", "slim", "overweight", "obese", "chubby",
  "stocky", ...) -> the muscle and weight sliders (Anny units 0..1) and, for weight words, the
  body-mass-index band the word allows;
- size words of the training captions (``ADJECTIVES``: "tall", "petite", "heavy-set", ...) ->
  height and waist-to-height targets (``SIZE_TARGETS``);
- numbers with units: height in cm, m, mm, feet and inches ("6'2\\"", "6 ft 2", "6-foot-2", "74
  inches tall"), weight in kg, lb or stone ("14 st 4 lb"), BMI, and the girths and lengths of
  the dataset's numeric texts (waist, chest, hip, arm, leg; cm or inches).

Everything combines ("a muscular 188 cm man, 92 kg"). What cannot be right is a ShapeMoveError
naming the conflict, never a silent guess: two genders, two heights, "an elderly 25-year-old",
"a tall 150 cm man", "an obese 2 m, 40 kg man" (BMI 10, and obese means BMI >= 30), "weighs 900 kg",
"a 2 cm man", a child's age (OpenBody's bodies are adults; teenagers by a small extrapolation),
a number without a unit ("weighs 90").

This is a leaf: it imports only ``errors``. The dataset builder's caption writer
(``data/shape_text.py``) and the body fit (``body/shape_from_measurements.py``) both use it.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from ..errors import ShapeMoveError

# ----------------------------------------------------------------------------------------------
# size words of the training captions (written by data/shape_text.py)
H_MIN, H_MAX = 130.0, 215.0   # heights the table covers (cm)
R_MIN, R_MAX = 0.28, 0.75     # waist-to-height ratios the table covers

# word -> ((height_cm low, high) or None, (WHtR low, high) or None); low inclusive, high exclusive.
# Height bands follow common usage for adults; the build bands are the usual WHtR bands (< 0.43
# slim, 0.43-0.53 average, > 0.53 heavy, > 0.60 very heavy).
ADJECTIVES: dict[str, tuple] = {
    # height
    "very short": ((H_MIN, 155.0), None),
    "short": ((155.0, 165.0), None),
    "of average height": ((165.0, 180.0), None),
    "tall": ((180.0, 190.0), None),
    "very tall": ((190.0, H_MAX), None),
    # build
    "slim": (None, (R_MIN, 0.43)),
    "slender": (None, (R_MIN, 0.43)),
    "thin": (None, (R_MIN, 0.43)),
    "of average build": (None, (0.43, 0.53)),
    "heavy-set": (None, (0.53, 0.60)),
    "heavy": (None, (0.53, 0.60)),
    "very heavy": (None, (0.60, R_MAX)),
    # both
    "average-sized": ((165.0, 180.0), (0.43, 0.53)),
    "petite": ((H_MIN, 165.0), (R_MIN, 0.43)),
    "lanky": ((180.0, H_MAX), (R_MIN, 0.43)),
    "stocky": ((H_MIN, 180.0), (0.53, R_MAX)),
    "big": ((180.0, H_MAX), (0.53, R_MAX)),
}
# what the fit aims at for a size word: (height cm or None, waist-to-height ratio or None), inside
# the word's ADJECTIVES ranges; the "average" words aim at nothing (the average body)
SIZE_TARGETS: dict[str, tuple] = {
    "very short": (150.0, None), "short": (160.0, None), "tall": (185.0, None), "very tall": (195.0, None),
    "slim": (None, 0.41), "slender": (None, 0.41), "thin": (None, 0.41),
    "heavy-set": (None, 0.565), "heavy": (None, 0.565), "very heavy": (None, 0.64),
    "petite": (155.0, 0.41), "lanky": (190.0, 0.41), "stocky": (170.0, 0.565), "big": (190.0, 0.565),
    "average-sized": (None, None), "of average height": (None, None), "of average build": (None, None),
}
SIZE_ALIASES = {"heavyset": "heavy-set", "heavy set": "heavy-set", "large": "big", "towering": "very tall",
                "average sized": "average-sized", "of medium height": "of average height",
                "of medium build": "of average build", "average build": "of average build",
                "average height": "of average height", "medium build": "of average build"}

# ----------------------------------------------------------------------------------------------
# gender: 0 = male .. 1 = female (OpenBody's slider)
MALE_WORDS = ("man", "men", "male", "boy", "guy", "gentleman", "he", "him", "his", "himself", "father", "dad",
              "husband", "grandfather", "grandpa", "granddad", "grandad", "son", "brother", "uncle", "nephew", "lad",
              "dude", "bloke", "fellow", "sir", "king", "prince", "businessman", "sportsman", "schoolboy",
              "boyfriend", "policeman", "fireman")
FEMALE_WORDS = ("woman", "women", "female", "girl", "lady", "she", "her", "hers", "herself", "mother", "mom", "mum",
                "wife", "grandmother", "grandma", "granny", "gran", "daughter", "sister", "aunt", "niece", "lass",
                "gal", "madam", "queen", "princess", "businesswoman", "sportswoman", "schoolgirl", "girlfriend",
                "policewoman", "ballerina")
GENDER_WORDS = {**{w: 0.0 for w in MALE_WORDS}, **{w: 1.0 for w in FEMALE_WORDS}}

# ----------------------------------------------------------------------------------------------
# age words: word -> (years, band low, band high); a stated age must lie in the band
AGE_WORDS: dict[str, tuple[float, float, float]] = {
    "very old": (85.0, 75.0, 110.0), "elderly": (75.0, 65.0, 110.0), "geriatric": (80.0, 65.0, 110.0),
    "old": (72.0, 62.0, 110.0), "aged": (72.0, 62.0, 110.0), "senior": (72.0, 62.0, 110.0), "pensioner": (72.0, 62.0, 110.0),
    "retired": (68.0, 58.0, 110.0), "older": (60.0, 45.0, 110.0),
    "middle aged": (48.0, 38.0, 62.0), "mature": (50.0, 35.0, 70.0),
    "young adult": (23.0, 18.0, 30.0), "young": (24.0, 16.0, 32.0), "youthful": (25.0, 16.0, 35.0),
    "college aged": (20.0, 18.0, 24.0), "twenty something": (25.0, 20.0, 29.0),
    "teenage": (16.0, 13.0, 19.0), "teenaged": (16.0, 13.0, 19.0), "teenager": (16.0, 13.0, 19.0),
    "teen": (16.0, 13.0, 19.0), "adolescent": (16.0, 13.0, 19.0),
    # a child: the youngest body the body model makes (PERSON_RANGES["age"]; OpenBody makes no younger),
    # "very short" unless a height is said (``CHILD_WORDS``)
    "child": (13.0, 13.0, 13.0), "children": (13.0, 13.0, 13.0), "kid": (13.0, 13.0, 13.0),
    "kids": (13.0, 13.0, 13.0), "youngster": (13.0, 13.0, 13.0),
}
CHILD_WORDS = ("child", "children", "kid", "kids", "youngster")
LITTLE_ONE = re.compile(r"\b(?:little|small) (?:boy|girl|son|daughter)s?\b")
# nouns that imply an age: a default when the text states none (never a conflict)
NOUN_AGES = {"boy": 16.0, "girl": 16.0, "schoolboy": 15.0, "schoolgirl": 15.0, "lad": 18.0, "lass": 18.0,
             "grandfather": 72.0, "grandpa": 72.0, "granddad": 72.0, "grandad": 72.0, "grandmother": 72.0,
             "grandma": 72.0, "granny": 75.0, "gran": 75.0}
DECADES = {"teens": 10, "twenties": 20, "thirties": 30, "forties": 40, "fifties": 50, "sixties": 60,
           "seventies": 70, "eighties": 80, "nineties": 90}


# ----------------------------------------------------------------------------------------------
# build words -> sliders (Anny units: muscle 0..0.97, weight 0..1) and the BMI band they allow
@dataclass(frozen=True)
class Build:
    muscle: float | None = None
    weight: float | None = None
    bmi: tuple[float, float] | None = None   # kg/m^2 band a stated weight must fall in
    bmi_target: float | None = None          # what the fit aims at when no weight is stated (non-size words)


BUILD_WORDS: dict[str, Build] = {
    # lean
    "underweight": Build(weight=0.0, bmi=(0, 19.0), bmi_target=17.5),
    "emaciated": Build(muscle=0.1, weight=0.0, bmi=(0, 18.0), bmi_target=16.5),
    "gaunt": Build(weight=0.0, bmi=(0, 20.0), bmi_target=17.5),
    "skinny": Build(weight=0.05, bmi=(0, 21.0), bmi_target=18.5),
    "scrawny": Build(muscle=0.15, weight=0.05, bmi=(0, 21.0), bmi_target=18.5),
    "bony": Build(weight=0.05, bmi=(0, 21.0), bmi_target=18.5),
    "thin": Build(weight=0.15, bmi=(0, 23.0)),
    "slim": Build(weight=0.25, bmi=(0, 25.0)),
    "slender": Build(weight=0.25, bmi=(0, 25.0)),
    "petite": Build(weight=0.3, bmi=(0, 25.0)),
    "lanky": Build(weight=0.2, bmi=(0, 24.0)),
    "wiry": Build(muscle=0.65, weight=0.2, bmi=(0, 24.0), bmi_target=20.5),
    "lean": Build(muscle=0.6, weight=0.3, bmi=(0, 26.0), bmi_target=21.5),
    # heavy
    "chubby": Build(weight=0.8, bmi=(24.0, 99), bmi_target=27.5),
    "plump": Build(weight=0.8, bmi=(24.0, 99), bmi_target=27.5),
    "pudgy": Build(weight=0.8, bmi=(24.0, 99), bmi_target=27.5),
    "chunky": Build(weight=0.8, bmi=(24.0, 99), bmi_target=28.0),
    "portly": Build(weight=0.85, bmi=(25.0, 99), bmi_target=29.0),
    "overweight": Build(weight=0.85, bmi=(24.5, 99), bmi_target=28.0),
    "heavy": Build(weight=0.85, bmi=(24.0, 99)),
    "heavy-set": Build(weight=0.85, bmi=(24.0, 99)),
    "stocky": Build(muscle=0.55, weight=0.75, bmi=(23.0, 99)),
    "big": Build(weight=0.8, bmi=(23.0, 99)),
    "very heavy": Build(weight=1.0, bmi=(27.0, 99)),
    "fat": Build(weight=0.95, bmi=(27.0, 99), bmi_target=31.0),
    "obese": Build(weight=1.0, bmi=(29.0, 99), bmi_target=33.0),
    "morbidly obese": Build(weight=1.0, bmi=(35.0, 99), bmi_target=42.0),
    "flabby": Build(muscle=0.1, weight=0.8, bmi=(24.0, 99), bmi_target=27.5),
    "out of shape": Build(muscle=0.15, weight=0.7),
    "unfit": Build(muscle=0.15, weight=0.65),
    # muscle
    "muscular": Build(muscle=0.85), "very muscular": Build(muscle=0.95), "muscly": Build(muscle=0.85),
    "brawny": Build(muscle=0.85, weight=0.7), "buff": Build(muscle=0.85), "jacked": Build(muscle=0.95),
    "ripped": Build(muscle=0.95, weight=0.35), "shredded": Build(muscle=0.95, weight=0.3),
    "chiseled": Build(muscle=0.85), "burly": Build(muscle=0.8, weight=0.8), "beefy": Build(muscle=0.85, weight=0.8),
    "hulking": Build(muscle=0.9, weight=0.85), "strong": Build(muscle=0.75), "powerful": Build(muscle=0.8),
    "well built": Build(muscle=0.8), "athletic": Build(muscle=0.75, weight=0.4), "fit": Build(muscle=0.72),
    "toned": Build(muscle=0.72, weight=0.35), "sporty": Build(muscle=0.7),
    "untoned": Build(muscle=0.15), "soft bodied": Build(muscle=0.15, weight=0.6),
    "frail": Build(muscle=0.1, weight=0.1, bmi=(0, 23.0)), "weak": Build(muscle=0.15), "puny": Build(muscle=0.1, weight=0.15),
    # sports: strength and power
    "bodybuilder": Build(muscle=0.97, weight=0.6), "powerlifter": Build(muscle=0.92, weight=0.85),
    "weightlifter": Build(muscle=0.9, weight=0.75), "strongman": Build(muscle=0.92, weight=0.9),
    "wrestler": Build(muscle=0.85, weight=0.7), "boxer": Build(muscle=0.8, weight=0.4),
    "rugby player": Build(muscle=0.85, weight=0.75), "shot putter": Build(muscle=0.88, weight=0.85),
    "linebacker": Build(muscle=0.85, weight=0.9), "sprinter": Build(muscle=0.85, weight=0.35),
    "gymnast": Build(muscle=0.85, weight=0.25), "lifter": Build(muscle=0.85, weight=0.6),
    # sports: endurance
    "marathon runner": Build(muscle=0.55, weight=0.1), "runner": Build(muscle=0.6, weight=0.2),
    "swimmer": Build(muscle=0.7, weight=0.35), "cyclist": Build(muscle=0.6, weight=0.2),
    "dancer": Build(muscle=0.6, weight=0.2), "ballerina": Build(muscle=0.55, weight=0.1),
}
MUSCLE_WORDS = tuple(w for w, b in BUILD_WORDS.items() if b.muscle is not None and b.muscle >= 0.7)

# ----------------------------------------------------------------------------------------------
# what a person can be (beyond: "impossible", never a body)
PERSON_RANGES = {"height_cm": (100.0, 250.0), "mass_kg": (25.0, 350.0), "bmi": (12.0, 70.0),
                 "age": (13.0, 110.0)}
MEASUREMENT_RANGES = {"chest_cm": (40, 200), "waist_cm": (30, 200), "hip_cm": (40, 200),
                      "arm_length_cm": (15, 110), "leg_length_cm": (30, 140)}
HEIGHT_MARGIN_CM = 3.0       # a stated height may lie this far outside its height word's band
HEIGHT_AGREE_CM = 2.5        # two stated heights must agree this well
BMI_AGREE = 1.5              # a stated BMI and the one of the stated height and weight
LB, ST, INCH = 0.45359237, 6.35029318, 2.54

GIRTH_NAMES = {"chest_cm": r"(?:chest|bust)", "waist_cm": r"waist", "hip_cm": r"(?:hips?|seat)"}


@dataclass
class ShapeWords:
    """What a shape text says. Sliders in OpenBody's units (gender 0 male..1 female, age years,
    muscle/weight Anny 0..1), None where the text says nothing; numbers in cm, kg, kg/m^2."""
    text: str = ""
    gender: float | None = None
    age: float | None = None
    age_implied: bool = False                    # the age came from a noun ("girl"), not stated
    muscle: float | None = None
    weight: float | None = None                  # weight slider from build words
    height_cm: float | None = None
    mass_kg: float | None = None
    bmi: float | None = None                     # stated BMI
    girths: dict = field(default_factory=dict)   # chest_cm, waist_cm, hip_cm, arm_length_cm, leg_length_cm
    size_words: list = field(default_factory=list)   # ADJECTIVES words, in order
    build_words: list = field(default_factory=list)  # BUILD_WORDS words, in order
    words: list = field(default_factory=list)        # every word or number understood, in order

    def phenotype(self) -> dict:
        """The sliders the text sets: {name: value} for gender, age, muscle, weight."""
        out = {"gender": self.gender, "age": self.age, "muscle": self.muscle, "weight": self.weight}
        return {k: v for k, v in out.items() if v is not None}

    def measurements(self) -> dict:
        """The stated measurements in cm (height and girths/lengths), as ``body.measure`` names them."""
        out = dict(self.girths)
        if self.height_cm is not None:
            out = {"height_cm": self.height_cm, **out}
        return out

    def bmi_band(self) -> tuple[float, float] | None:
        """The BMI band the build words allow together (their intersection), or None."""
        bands = [BUILD_WORDS[w].bmi for w in self.build_words if BUILD_WORDS[w].bmi is not None]
        if not bands:
            return None
        return max(b[0] for b in bands), min(b[1] for b in bands)

    def bmi_target(self) -> float | None:
        """The BMI the build words aim at when the text states no weight (the words that are no
        size word of the captions: "obese", "skinny", ...), or None."""
        ts = [BUILD_WORDS[w].bmi_target for w in self.build_words if BUILD_WORDS[w].bmi_target is not None]
        return sum(ts) / len(ts) if ts else None

    def __bool__(self) -> bool:
        return bool(self.words)


# ----------------------------------------------------------------------------------------------
# numbers
_N = r"(\d+(?:[.,]\d+)?)"


def _num(s: str) -> float:
    return float(s.replace(",", "."))


def _normalise(text: str) -> str:
    t = text.lower()
    t = re.sub(r"(?<![\d.])(\d+(?:\.\d+)?)\s*(?:-|to)\s*(\d+(?:\.\d+)?)(?=\s*[a-z'\"])",
               lambda m: f"{(float(m.group(1)) + float(m.group(2))) / 2:g}", t)  # "170-180 cm": the middle
    for a, b in (("\u2019", "'"), ("\u2032", "'"), ("\u2033", '"'), ("\u201d", '"'), ("\u201c", '"'),
                 ("\u2212", "-"), ("\u2013", "-"), ("\u00a0", " "), ("''", '"')):
        t = t.replace(a, b)
    return t


class _Text:
    """The text with the parts already read blanked out (so a number is read once)."""

    def __init__(self, text: str):
        self.t = text

    def take(self, pattern: str):
        """Every match of ``pattern`` (left to right), each blanked out after reading."""
        out = []
        for m in re.finditer(pattern, self.t):
            out.append(m)
        for m in out:
            self.t = self.t[:m.start()] + " " * (m.end() - m.start()) + self.t[m.end():]
        return out


_GIRTH_UNIT = r"\s*(cm|centimet(?:er|re)s?|in(?:ch(?:es)?)?\b|\")?"
_LENGTH = {"arm_length_cm": r"arm(?:s)?(?: length)?", "leg_length_cm": r"leg(?:s)?(?: length)?"}


def _girth_value(value: str, unit: str | None) -> float:
    v = _num(value)
    return v * INCH if unit and unit.startswith(("in", '"')) else v


def _read_girths(tx: _Text, out: ShapeWords) -> None:
    for key, name in {**GIRTH_NAMES, **_LENGTH}.items():
        pats = [r"\b" + name + r"(?: circumference| girth| measurement| size)?(?: of| is| measuring| at|:)?\s*" + _N + _GIRTH_UNIT,
                r"\b" + _N + r"\s*-?\s*(cm|in|inch|inches|\")?\s*-?\s*" + name + r"\b"]
        for p in pats:
            for m in tx.take(p):
                v = _girth_value(m.group(1), m.group(2))
                _set(out, "girths", key, v, m.group(0))


def _set(out: ShapeWords, where: str, key: str, value: float, said: str) -> None:
    store = out.girths if where == "girths" else None
    old = store.get(key) if store is not None else getattr(out, key)
    if old is not None and abs(old - value) > (HEIGHT_AGREE_CM if key != "mass_kg" else 2.0):
        name = key.replace("_cm", "").replace("_kg", "").replace("_", " ")
        raise ShapeMoveError(f"the shape text states two different {name}s ({old:g} and {value:g}): "
                             f"'{said.strip()}' disagrees; keep one")
    if store is not None:
        store[key] = value
    else:
        setattr(out, key, value)
    out.words.append(said.strip())


_TALL = r"(?:\s*(?:tall|high|in height)\b)?"  # read with the height: "160 cm tall" is no size word "tall"
_HEIGHT_BEFORE = r"\b(?:height|stands?|standing)\s*(?:of|is|:)?\s*"


def _read_heights(tx: _Text, out: ShapeWords, context: bool = False) -> None:
    """Heights in feet/inches, inches, mm/cm/m. ``context``: only those said to be heights ("...
    tall", "height ...", "stands ..."), so that "walks 5 m forward" in a motion caption is none."""
    ft = r"(?:'|ft\.?|feet|foot)"
    inch = r"(?:\"|in\b\.?|inch(?:es)?\b)"
    tall = r"\s*(?:tall|high|in height)\b" if context else _TALL

    def forms(core: str) -> list[str]:
        return [_HEIGHT_BEFORE + core, core + tall] if context else [core + tall]

    for p in forms(r"(?<![\d.])(\d)\s*-?\s*" + ft + r"(?:\s*,?\s*-?\s*(\d{1,2}(?:\.\d+)?)(?!\d)\s*" + inch + r"?)?"):
        for m in tx.take(p):
            feet, inches = int(m.group(1)), _num(m.group(2)) if m.group(2) else 0.0
            if inches >= 12:
                raise ShapeMoveError(f"'{m.group(0).strip()}': inches run 0-11 after the feet")
            _set(out, "", "height_cm", (feet * 12 + inches) * INCH, m.group(0))
    for m in tx.take(r"(?<![\d.])" + _N + r"\s*" + inch + r"\s*(?:tall|high|in height)\b"):
        _set(out, "", "height_cm", _num(m.group(1)) * INCH, m.group(0))
    scale = {"mm": 0.1, "milli": 0.1, "cm": 1.0, "centi": 1.0, "m": 100.0, "met": 100.0}
    for p in forms(r"(?<![\d.])" + _N + r"\s*(mm|millimet(?:er|re)s?|cm|centimet(?:er|re)s?|m|met(?:er|re)s?)\b"):
        for m in tx.take(p):
            unit = m.group(2)
            k = next(v for u, v in scale.items() if unit.startswith(u))
            _set(out, "", "height_cm", _num(m.group(1)) * k, m.group(0))


def _read_mass(tx: _Text, out: ShapeWords) -> None:
    for m in tx.take(r"(?<![\d.])" + _N + r"\s*(?:st|stones?)\b(?:\s*,?\s*(\d{1,2}(?:\.\d+)?)\s*(?:lbs?|pounds?)\b)?"):
        _set(out, "", "mass_kg", _num(m.group(1)) * ST + (_num(m.group(2)) * LB if m.group(2) else 0.0), m.group(0))
    for m in tx.take(r"(?<![\d.])" + _N + r"\s*(?:kg|kgs|kilo(?:gram)?s?|kilogrammes?)\b"):
        _set(out, "", "mass_kg", _num(m.group(1)), m.group(0))
    for m in tx.take(r"(?<![\d.])" + _N + r"\s*(?:lbs?|pounds?)\b"):
        _set(out, "", "mass_kg", _num(m.group(1)) * LB, m.group(0))
    for m in tx.take(r"\b(?:bmi|body mass index)\s*(?:of|is|:|=|at|around|about)?\s*" + _N + r"|(?<![\d.])" + _N + r"\s*bmi\b"):
        _set(out, "", "bmi", _num(m.group(1) or m.group(2)), m.group(0))


def _read_age(tx: _Text, out: ShapeWords) -> None:
    ages = []
    for m in tx.take(r"(?<![\d.])" + _N + r"\s*-?\s*(?:years?|yrs?|y\.?o\.?\b|y/o)(?:\s*-?\s*old)?"):
        ages.append((_num(m.group(1)), m.group(0)))
    for m in tx.take(r"\bage(?:d)?\s*(?:of|is|:)?\s*" + _N):
        ages.append((_num(m.group(1)), m.group(0)))
    dec = "|".join(DECADES) + r"|\d0'?s"
    for m in tx.take(r"\bin\s+(his|her|their|the)\s+(early|mid|late)?[\s-]*(" + dec + r")\b"):
        word = m.group(3)
        base = DECADES.get(word) if word in DECADES else int(word[:2])
        base = 13 if base == 10 else base
        ages.append((base + {"early": 2, "mid": 5, "late": 8}.get(m.group(2) or "mid", 5)
                     if base != 13 else 16, m.group(0)))
        s, e = m.span(1)   # the pronoun stays for the gender words ("in her sixties")
        tx.t = tx.t[:s] + m.group(1) + tx.t[e:]
    for v, said in ages:
        if out.age is not None and abs(out.age - v) > 2:
            raise ShapeMoveError(f"the shape text states two ages ({out.age:g} and {v:g}); keep one")
        out.age = v
        out.words.append(said.strip())


_WORDS_CACHE: dict = {}


def _phrase_pattern(words) -> re.Pattern:
    key = tuple(words)
    if key not in _WORDS_CACHE:
        alts = sorted({w.replace("-", " ") for w in words}, key=len, reverse=True)
        _WORDS_CACHE[key] = re.compile(r"(?<![a-z])(" + "|".join(re.escape(a).replace(r"\ ", r"\s+") for a in alts)
                                       + r")(?![a-z])")
    return _WORDS_CACHE[key]


def _canon(phrase: str, table) -> str:
    """'heavy  set' -> the table's spelling ('heavy-set')."""
    flat = re.sub(r"\s+", " ", phrase)
    for w in table:
        if w.replace("-", " ") == flat:
            return w
    return flat


def _read_words(text: str, out: ShapeWords) -> None:
    t = re.sub(r"[^a-z']+", " ", text.replace("-", " "))
    t = " " + re.sub(r"'s\b", "", t) + " "
    # age words first ("young adult" before "adult"), then build/size words, then gender nouns
    age_hits = ["child"] if LITTLE_ONE.search(t) else []   # "a little girl": a child, and a girl
    for m in _phrase_pattern(AGE_WORDS).finditer(t):
        age_hits.append(_canon(m.group(1), AGE_WORDS))
    t = _phrase_pattern(AGE_WORDS).sub(" ", t)
    vocab = list(BUILD_WORDS) + list(SIZE_TARGETS) + list(SIZE_ALIASES)
    for m in _phrase_pattern(vocab).finditer(t):
        w = _canon(m.group(1), vocab)
        w = SIZE_ALIASES.get(w, w)
        if w in SIZE_TARGETS and w not in out.size_words:
            out.size_words.append(w)
        if w in BUILD_WORDS and w not in out.build_words:
            out.build_words.append(w)
        out.words.append(w)
    t = _phrase_pattern(vocab).sub(" ", t)
    if any(w in CHILD_WORDS for w in age_hits) and not any(ADJECTIVES[w][0] for w in out.size_words
                                                           if w in ADJECTIVES):
        out.size_words.append("very short")   # the smallest the words can ask for
    genders = []
    for m in _phrase_pattern(GENDER_WORDS).finditer(t):
        w = _canon(m.group(1), GENDER_WORDS)
        genders.append(w)
        out.words.append(w)
    _combine_gender(genders, out)
    _combine_age(age_hits, genders, out)
    _combine_build(out)


def _combine_gender(genders: list[str], out: ShapeWords) -> None:
    values = {GENDER_WORDS[w] for w in genders}
    if len(values) > 1:
        male = next(w for w in genders if GENDER_WORDS[w] == 0.0)
        female = next(w for w in genders if GENDER_WORDS[w] == 1.0)
        raise ShapeMoveError(f"the shape text names a man and a woman ('{male}' and '{female}'): describe one body")
    if values:
        out.gender = values.pop()


def _combine_age(age_hits: list[str], genders: list[str], out: ShapeWords) -> None:
    for w in age_hits:
        out.words.append(w)
    if age_hits:
        lo = max(AGE_WORDS[w][1] for w in age_hits)
        hi = min(AGE_WORDS[w][2] for w in age_hits)
        if lo > hi:
            raise ShapeMoveError(f"the shape text's age words disagree: {' and '.join(repr(w) for w in age_hits)}")
        if out.age is not None:
            bad = [w for w in age_hits if not AGE_WORDS[w][1] <= out.age <= AGE_WORDS[w][2]]
            if bad:
                w = bad[0]
                raise ShapeMoveError(f"the shape text says '{w}' ({AGE_WORDS[w][1]:g}-{AGE_WORDS[w][2]:g} years) "
                                     f"and {out.age:g} years old: they disagree")
        else:
            out.age = min(max(sum(AGE_WORDS[w][0] for w in age_hits) / len(age_hits), lo), hi)
            fits = [NOUN_AGES[w] for w in genders if w in NOUN_AGES and lo <= NOUN_AGES[w] <= hi]
            if fits:   # "a young girl": the girl's 16 is young, and nearer what is meant than young's 24
                out.age = fits[0]
    if out.age is None:
        implied = [NOUN_AGES[w] for w in genders if w in NOUN_AGES]
        if implied:
            out.age, out.age_implied = implied[0], True
    if out.age is not None:
        lo, hi = PERSON_RANGES["age"]
        if out.age < lo:
            raise ShapeMoveError(f"the shape text asks for a child ({out.age:g} years): the body model makes adults "
                                 f"and teenagers ({lo:g} years and up)")
        if out.age > hi:
            raise ShapeMoveError(f"{out.age:g} years is no age a person reaches (up to {hi:g})")


def _combine_build(out: ShapeWords) -> None:
    # heights: height words whose bands do not overlap ("tall and stocky": the word that says only
    # a height wins over the height a build word implies, see ``size_targets``)
    hwords = [w for w in out.size_words if ADJECTIVES[w][0] is not None and w not in ("average-sized",)]
    if any(ADJECTIVES[w][1] is None for w in hwords):
        hwords = [w for w in hwords if ADJECTIVES[w][1] is None]
    for a in hwords:
        for b in hwords:
            ra, rb = ADJECTIVES[a][0], ADJECTIVES[b][0]
            if a < b and (ra[1] <= rb[0] or rb[1] <= ra[0]):
                raise ShapeMoveError(f"the shape text's height words disagree: '{a}' and '{b}'")
    band = out.bmi_band()
    if band is not None and band[0] > band[1]:
        ws = [w for w in out.build_words if BUILD_WORDS[w].bmi is not None]
        raise ShapeMoveError(f"the shape text's build words disagree: {' and '.join(repr(w) for w in ws)}")
    rwords = [w for w in out.size_words if ADJECTIVES[w][1] is not None]
    for a in rwords:
        for b in rwords:
            ra, rb = ADJECTIVES[a][1], ADJECTIVES[b][1]
            if a < b and (ra[1] <= rb[0] or rb[1] <= ra[0]) and "average" not in a + b:
                raise ShapeMoveError(f"the shape text's build words disagree: '{a}' and '{b}'")
    muscles = [(w, BUILD_WORDS[w].muscle) for w in out.build_words if BUILD_WORDS[w].muscle is not None]
    if muscles:
        vals = [m for _, m in muscles]
        if max(vals) - min(vals) > 0.5:
            hi = max(muscles, key=lambda x: x[1])[0]
            lo = min(muscles, key=lambda x: x[1])[0]
            raise ShapeMoveError(f"the shape text's build words disagree: '{hi}' and '{lo}'")
        out.muscle = max(vals) if min(vals) >= 0.5 else sum(vals) / len(vals)
    weights = [(w, BUILD_WORDS[w].weight) for w in out.build_words if BUILD_WORDS[w].weight is not None]
    pure = [(w, v) for w, v in weights if (BUILD_WORDS[w].muscle or 0.0) < 0.7]
    weights = pure or weights   # "a skinny bodybuilder": the weight word says the weight, the sport the muscle
    if weights:
        hi = max(weights, key=lambda x: x[1])
        lo = min(weights, key=lambda x: x[1])
        if hi[1] - lo[1] > 0.5:
            raise ShapeMoveError(f"the shape text's build words disagree: '{lo[0]}' and '{hi[0]}'")
        weights = [v for _, v in weights]
        out.weight = sum(weights) / len(weights)


def _check_numbers(out: ShapeWords) -> None:
    for key in ("height_cm", "mass_kg", "bmi"):
        v = getattr(out, key)
        if v is None:
            continue
        lo, hi = PERSON_RANGES[key]
        if not lo <= v <= hi:
            unit = {"height_cm": "cm", "mass_kg": "kg", "bmi": "kg/m^2 BMI"}[key]
            what = {"height_cm": "tall", "mass_kg": "in weight", "bmi": ""}[key]
            raise ShapeMoveError(f"no person is {v:g} {unit} {what}".rstrip() + f": a body is {lo:g}-{hi:g} {unit}")
    for key, v in out.girths.items():
        lo, hi = MEASUREMENT_RANGES[key]
        if not lo <= v <= hi:
            raise ShapeMoveError(f"{key.replace('_cm', '').replace('_', ' ')} {v:g} cm is outside the plausible "
                                 f"range [{lo}, {hi}] cm")
    if out.height_cm is not None:
        for w in out.size_words:
            if ADJECTIVES[w][1] is not None and ADJECTIVES[w][0] is not None:
                continue  # petite, lanky, stocky, big: mostly a build; a stated height decides the height
            rng = ADJECTIVES[w][0]
            if rng is not None and SIZE_TARGETS[w][0] is not None and not (
                    rng[0] - HEIGHT_MARGIN_CM <= out.height_cm < rng[1] + HEIGHT_MARGIN_CM):
                raise ShapeMoveError(f"'{w}' ({rng[0]:g}-{rng[1]:g} cm) and {out.height_cm:.0f} cm tall disagree")
    if out.bmi is not None and out.height_cm is not None and out.mass_kg is not None:
        b = out.mass_kg / (out.height_cm / 100) ** 2
        if abs(b - out.bmi) > BMI_AGREE:
            raise ShapeMoveError(f"BMI {out.bmi:g} disagrees with {out.height_cm:.0f} cm and {out.mass_kg:.0f} kg "
                                 f"(BMI {b:.1f}); state two of the three")
    bmi = stated_bmi(out)
    if bmi is not None:
        lo, hi = PERSON_RANGES["bmi"]
        if not lo <= bmi <= hi:
            raise ShapeMoveError(f"{out.height_cm:.0f} cm and {out.mass_kg:.0f} kg make a BMI of {bmi:.1f}: no living "
                                 f"body has that (BMI {lo:g}-{hi:g})" + word_conflict(out, bmi))
        msg = word_conflict(out, bmi)
        if msg:
            raise ShapeMoveError(f"the shape text contradicts itself: BMI {bmi:.1f}" + msg)


def size_targets(out: ShapeWords) -> tuple[float | None, float | None]:
    """(height cm, waist-to-height ratio) the size words aim at, None where none: the mean over the
    words that say it, a word that says only a height (or only a build) winning over one that says
    both ("tall and stocky": 185 cm, the waist of "stocky")."""
    def pick(i: int) -> float | None:
        ws = [w for w in out.size_words if SIZE_TARGETS[w][i] is not None]
        pure = [w for w in ws if ADJECTIVES[w][1 - i] is None]
        ws = pure or ws
        return sum(SIZE_TARGETS[w][i] for w in ws) / len(ws) if ws else None

    return pick(0), pick(1)


def stated_bmi(out: ShapeWords) -> float | None:
    """The BMI the text states, directly or by height and weight; None if it does not."""
    if out.bmi is not None:
        return out.bmi
    if out.height_cm is not None and out.mass_kg is not None:
        return out.mass_kg / (out.height_cm / 100) ** 2
    return None


def word_conflict(out: ShapeWords, bmi: float) -> str:
    """'' or ', but "obese" means BMI >= 29' for the first build word whose band excludes bmi."""
    for w in out.build_words:
        band = BUILD_WORDS[w].bmi
        if band is not None and not band[0] <= bmi <= band[1]:
            need = f">= {band[0]:g}" if band[1] >= 99 else f"<= {band[1]:g}" if band[0] <= 0 else f"{band[0]:g}-{band[1]:g}"
            return f', but "{w}" means BMI {need}'
    return ""


_UNPLACED = re.compile(r"(?<![a-z])\d+(?:[.,]\d+)?")


def parse_shape_words(text: str) -> ShapeWords:
    """Everything ``text`` says about a body (see the module docstring); ShapeMoveError for a
    contradiction, an impossible body or a number it cannot place."""
    if not isinstance(text, str):
        raise ShapeMoveError(f"the shape text must be a string, got {type(text).__name__}")
    t = _normalise(text)
    neg = re.search(r"(?<![\w.])-\s*\d", t)
    if neg:
        raise ShapeMoveError(f"the shape text states a negative number ({text[neg.start():neg.end() + 8].strip()!r}); "
                             "body measurements are positive, e.g. '170 cm tall'")
    out = ShapeWords(text=text)
    tx = _Text(t)
    _read_girths(tx, out)
    _read_age(tx, out)
    _read_mass(tx, out)
    _read_heights(tx, out)
    left = _UNPLACED.search(tx.t)
    if left:
        around = tx.t[max(0, left.start() - 12):left.end() + 12].strip()
        raise ShapeMoveError(f"cannot read the number in '{around}': give it a unit, e.g. '182 cm tall', '1.82 m', "
                             "'6 ft 2', '92 kg', '200 lb', '35 years old', 'waist 90 cm'")
    _read_words(tx.t, out)
    _check_numbers(out)
    return out


def parse_shape_text(text: str) -> dict:
    """The measurements a text states, in cm (only those present; ``ShapeWords.measurements``
    names): heights said to be heights ("182 cm tall", "1.82 m tall", "6 ft 0 in tall", "5'11\\"
    tall", "height 182 cm") and girths/lengths ("waist 100 cm", "a 39-inch waist", "chest
    circumference of 101 cm"). Lenient, for motion captions with a shape mixed in: other numbers
    ("walks 5 m forward", "turns 180 degrees") are no measurement and no error; shape texts go
    through ``parse_shape_words``, which places every number or refuses the text."""
    out = ShapeWords(text=str(text))
    tx = _Text(_normalise(str(text)))
    _read_girths(tx, out)
    _read_heights(tx, out, context=True)
    return out.measurements()
