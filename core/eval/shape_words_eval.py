"""Bodies the text describes: man or woman, age, build, weight (issue #25's targets).

    res = eval_shape_words(path="auto", texts=200)       # the parser + fit (no model needed)
    res = eval_shape_words(path="head", texts=200)       # the [BETA] head alone (the T5 reads the text)

Sets of ``texts`` generated shape texts each (deterministic for a seed), every body read back the
way the issue asks: the phenotype sliders by least squares from the betas through OpenBody's
shipped map (``PhenotypeMap.from_betas``), height and girths on the mesh, mass from the mesh volume
(``body.measure``: x 985 kg/m^3).

- gender: varied texts naming a man or a woman (nouns, pronouns, with age, build, size words and
  numbers); the share with the gender slider <= 0.25 for men, >= 0.75 for women; and the same text
  with the other noun: chest and hip girths compared (a man's chest, a woman's hips);
- age: texts with an age word; the share in its band (elderly words >= 65 years, young adult
  <= 30, teenage <= 19; read-back ages are clipped to the map's 18-80);
- muscle: texts with a muscle word ("muscular", "ripped", strength sports); the share >= 0.7;
- numeric: texts stating height and weight in cm, m, ft/in, kg, lb, st (with or without words);
  the share with the body within 1 cm and 2 kg of both numbers as stated;
- no shape words: motion prompts with no shape text; their body against the average adult
  (the map's default sliders, betas 0), for several seeds (``generate`` itself when ``seeds``).

``path``: "auto" is what ``Request(shape_from="auto")`` gives (words and numbers the parser reads ->
``body.shape_from_measurements.betas_for_shape_text``; free text -> the [BETA] head), "head" what
``shape_from="head"`` gives (the head reads every text).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from ..text.shape_words import AGE_WORDS, BUILD_WORDS, INCH, LB, ST
from .report import show_result

MOTION = ("a person walks forward.", "someone waves with the right hand.", "a person jumps in place.")
NO_SHAPE_PROMPTS = ("a person nods", "someone walks forward", "a person waves with both hands", "someone sits down",
                    "a person jumps in place")
NOUNS = [("man", "woman"), ("guy", "lady"), ("gentleman", "lady"), ("male", "female"), ("father", "mother"),
         ("husband", "wife"), ("brother", "sister"), ("dad", "mum"), ("boy", "girl"),
         ("grandfather", "grandmother"), ("grandpa", "grandma")]
PRONOUNS = ("he", "she")
AGE_BANDS = {"elderly": (["elderly", "old", "senior", "very old", "aged", "geriatric"], 65.0, 200.0),
             "young adult": (["young", "young adult", "youthful"], 0.0, 30.0),
             "teenage": (["teenage", "teenager", "teen", "adolescent"], 0.0, 19.0)}
MUSCLE_TEST_WORDS = ["muscular", "very muscular", "ripped", "jacked", "buff", "brawny", "shredded", "hulking",
                     "bodybuilder", "powerlifter", "weightlifter", "strongman", "wrestler", "rugby player",
                     "shot putter"]
HEIGHT_WORDS = ["tall", "short", "very tall", "petite", "lanky"]
WEIGHT_WORDS = ["slim", "skinny", "heavy-set", "overweight", "chubby", "obese", "athletic", "lean", "thin",
                "slender", "stocky"]
MALE_HEIGHT, FEMALE_HEIGHT = (176.0, 7.0), (163.0, 6.5)   # cm, mean and sd of the numeric texts


def _article(w: str) -> str:
    return "an" if w[:1] in "aeiou" else "a"


def _height_text(rng, h: float) -> tuple[str, float]:
    """A height in one of the units people type, and the value it states (cm)."""
    k = rng.integers(5)
    if k == 0:
        return f"{h:.0f} cm", float(round(h))
    if k == 1:
        return f"{h / 100:.2f} m", round(h / 100, 2) * 100
    inches = int(round(h / INCH))
    ft, i = divmod(inches, 12)
    form = [f"{ft} ft {i}", f"{ft}'{i}\"", f"{ft} feet {i} inches"][k - 2]
    return form, inches * INCH


def _mass_text(rng, kg: float) -> tuple[str, float]:
    k = rng.integers(4)
    if k <= 1:
        return f"{kg:.0f} kg", float(round(kg))
    if k == 2:
        lb = round(kg / LB)
        return f"{lb} lb", lb * LB
    st, lb = divmod(int(round(kg / LB)), 14)
    return f"{st} st {lb} lb", st * ST + lb * LB


def _phrase(rng, noun: str, adjs: list[str], nums: list[str], age_years: int | None) -> str:
    """One of several sentence shapes around a noun, its adjectives and its numbers."""
    adj = ", ".join(adjs)
    lead = f"{_article(adj or noun)} {adj + ' ' if adj else ''}{noun}"
    age = f"{age_years}-year-old " if age_years is not None else ""
    if age:
        lead = f"{_article(age)} {age}{adj + ' ' if adj else ''}{noun}"
    k = rng.integers(4)
    if not nums:
        return [lead, f"{lead}.", f"the {noun} is {' and '.join(adjs)}" if adjs and not age else lead, lead][k]
    joined = ", ".join(nums)
    return [f"{lead}, {joined}", f"{lead} who is {' and '.join(nums)}", f"{lead} ({joined})", f"{lead}: {joined}"][k]


def _numbers(rng, female: bool, build: str | None, height_word: str | None) -> tuple[list[str], float, float]:
    """[height text, weight text] in a random order for a body (consistent with its words) and the
    values they state (cm, kg)."""
    mu, sd = FEMALE_HEIGHT if female else MALE_HEIGHT
    h = float(np.clip(rng.normal(mu, sd), mu - 2 * sd, mu + 2 * sd))
    if height_word in ("tall",):
        h = float(rng.uniform(181, 189))
    elif height_word in ("very tall", "lanky"):
        h = float(rng.uniform(191, 197))
    elif height_word in ("short",):
        h = float(rng.uniform(156, 164))
    elif height_word in ("petite",):
        h = float(rng.uniform(150, 163))
    lo, hi = (19.0, 30.0)
    if build is not None and BUILD_WORDS[build].bmi is not None:
        b0, b1 = BUILD_WORDS[build].bmi
        lo, hi = max(lo, b0 + 0.8), min(max(hi, b0 + 4), b1 - 0.8)
    bmi = float(rng.uniform(lo, hi))
    ht, hv = _height_text(rng, h)
    mt, mv = _mass_text(rng, bmi * (hv / 100) ** 2)
    return ([ht, mt] if rng.random() < 0.5 else [mt, ht]), hv, mv


def gender_texts(n: int, seed: int) -> list[dict]:
    """``n`` texts, each with its twin naming the other sex: {"text", "swapped", "female"}."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        female = bool(i % 2)
        pair = NOUNS[rng.integers(len(NOUNS))]
        adjs, nums, age = [], [], None
        if rng.random() < 0.4:
            adjs.append(HEIGHT_WORDS[rng.integers(len(HEIGHT_WORDS))])
        if rng.random() < 0.5 and not set(adjs) & {"petite", "lanky"}:   # those two say the build already
            adjs.append(WEIGHT_WORDS[rng.integers(len(WEIGHT_WORDS))])
        if pair[0] not in ("boy", "grandfather", "grandpa") and rng.random() < 0.3:
            age = int(rng.integers(20, 70))
        pronoun = rng.random() < 0.2
        if rng.random() < 0.3 and not pronoun:
            build = next((a for a in adjs if a in BUILD_WORDS), None)
            hw = next((a for a in adjs if a in HEIGHT_WORDS), None)
            nums, _, _ = _numbers(rng, female, build, hw)
        if pronoun:
            desc = " and ".join(adjs) or "of average build"
            t = f"{{p}} is {desc}" + (f", {age} years old" if age else "")
            text, swapped = t.format(p=PRONOUNS[female]), t.format(p=PRONOUNS[1 - female])
        else:
            text = _phrase(np.random.default_rng(seed * 7919 + i), pair[female], adjs, nums, age)
            swapped = _phrase(np.random.default_rng(seed * 7919 + i), pair[1 - female], adjs, nums, age)
        out.append({"text": text, "swapped": swapped, "female": female})
    return out


def age_texts(n: int, seed: int) -> list[dict]:
    """``n`` texts with an age word: {"text", "band", "lo", "hi"} (the band's limits in years)."""
    rng = np.random.default_rng(seed + 1)
    bands = list(AGE_BANDS)
    out = []
    for i in range(n):
        band = bands[i % len(bands)]
        words, lo, hi = AGE_BANDS[band]
        w = words[rng.integers(len(words))]
        female = bool(rng.integers(2))
        noun = (["person", "man", "guy", "boy"] if not female else ["person", "woman", "lady", "girl"])[rng.integers(4)]
        if band != "teenage" and noun in ("boy", "girl"):
            noun = "man" if not female else "woman"
        if w in ("teenager", "teen", "adolescent") and rng.random() < 0.5:
            text = f"{_article(w)} {w}" if w != "teen" else f"a {noun} in {'her' if female else 'his'} teens"
        else:
            adjs = [w]
            if rng.random() < 0.4:
                adjs.insert(0, (HEIGHT_WORDS + WEIGHT_WORDS)[rng.integers(len(HEIGHT_WORDS) + len(WEIGHT_WORDS))])
            if "stocky" in adjs and any(a in ("petite", "lanky") for a in adjs):
                adjs.remove("stocky")
            nums = []
            if rng.random() < 0.25:
                build = next((a for a in adjs if a in BUILD_WORDS), None)
                hw = next((a for a in adjs if a in HEIGHT_WORDS), None)
                nums, _, _ = _numbers(rng, female, build, hw)
            text = _phrase(rng, noun, adjs, nums, None)
        out.append({"text": text, "band": band, "lo": lo, "hi": hi})
    return out


def muscle_texts(n: int, seed: int) -> list[dict]:
    rng = np.random.default_rng(seed + 2)
    out = []
    for i in range(n):
        w = MUSCLE_TEST_WORDS[i % len(MUSCLE_TEST_WORDS)]
        female = bool(rng.integers(2))
        noun = ["person", "man", "woman", "guy", "lady"][rng.integers(5)]
        adjs, nums = [], []
        if rng.random() < 0.3:
            adjs.append(["young", "middle-aged", "tall", "short", "elderly"][rng.integers(5)])
        if rng.random() < 0.25:
            hw = next((x for x in adjs if x in HEIGHT_WORDS), None)
            nums, _, _ = _numbers(rng, female or noun in ("woman", "lady"), None, hw)
        if w in ("bodybuilder", "powerlifter", "weightlifter", "strongman", "wrestler", "rugby player", "shot putter"):
            text = _phrase(rng, w if rng.random() < 0.6 else f"{noun} who is a {w}", adjs, nums, None)
        else:
            text = _phrase(rng, noun, adjs + [w], nums, None)
        out.append({"text": text, "word": w})
    return out


def numeric_texts(n: int, seed: int) -> list[dict]:
    """{"text", "height_cm", "mass_kg"}: the height and weight as the text states them."""
    rng = np.random.default_rng(seed + 3)
    out = []
    for i in range(n):
        female = bool(i % 2)
        noun = (["person", "man", "guy", "male"] if not female else ["person", "woman", "lady", "female"])[rng.integers(4)]
        adjs = []
        if rng.random() < 0.3:
            adjs.append(["muscular", "elderly", "young", "middle-aged", "athletic"][rng.integers(5)])
        nums, h, kg = _numbers(rng, female and noun != "person", None, None)
        ht, mt = sorted(nums, key=lambda x: x.endswith(("kg", "lb")))   # height text, weight text
        form = rng.integers(4)
        if form == 0:
            text = _phrase(rng, noun, adjs, nums, None)
        elif form == 1:
            text = f"{'she' if female else 'he'} is {nums[0]} and {nums[1]}" if noun != "person" else ", ".join(nums)
        elif form == 2:
            text = f"weighs {mt}, stands {ht} tall"
        else:
            text = f"height {ht}, weight {mt}"
        out.append({"text": text, "height_cm": h, "mass_kg": kg})
    return out


class _Reader:
    """Betas for shape texts on a path ("auto": parser + fit, free text to the head; "head")."""

    def __init__(self, path: str, model_dir=None):
        from ..body.load import load_body_model

        if path not in ("auto", "head"):
            raise ShapeMoveError(f"path must be 'auto' or 'head', got {path!r}")
        self.path, self.model_dir = path, model_dir
        self.body = load_body_model(None)
        self._t5 = None
        self.free = 0          # texts the parser left to the head
        self.refused: list = []  # (text, message) the parser (or on the head path, the head) refused

    def t5(self):
        if self._t5 is None:
            from ..generation.model_bundle import model_files, resolve_model_dir
            from ..models.shapemove_t5 import ShapeMoveT5

            t5_dir = model_files(resolve_model_dir(self.model_dir))["t5"]
            if not t5_dir.is_dir():
                raise ShapeMoveError(f"{t5_dir.parent} has no t5/ model: the [BETA] head lives there")
            self._t5 = ShapeMoveT5.load(t5_dir)
        return self._t5

    def head(self, texts: list[str | None], captions=None) -> np.ndarray:
        """The head's betas; NaN rows for texts it refuses (recorded in ``refused``)."""
        from .shape_eval import head_readings

        t5, reader = self.t5()
        caps = list(captions) if captions is not None else [MOTION[i % len(MOTION)] for i in range(len(texts))]
        betas, refused = head_readings(t5, reader, caps, list(texts))
        self.refused += refused
        return betas

    def betas(self, texts: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """(N,10) betas and (N,) bool: read (False: refused by the parser or the head, betas NaN)."""
        from ..body.shape_from_measurements import betas_for_shape_text

        if self.path == "head":
            b = self.head(texts)
            return b, ~np.isnan(b).any(1)
        out = np.full((len(texts), self.body.num_betas), np.nan)
        ok = np.ones(len(texts), bool)
        free = []
        for i, t in enumerate(texts):
            try:
                b = betas_for_shape_text(self.body, t)
            except ShapeMoveError as exc:
                self.refused.append((t, str(exc)))
                ok[i] = False
                continue
            if b is None:
                free.append(i)
            else:
                out[i] = b
        if free:
            self.free += len(free)
            out[free] = self.head([texts[i] for i in free])
        return out, ok & ~np.isnan(out).any(1)


def _readback(body, betas: np.ndarray) -> np.ndarray:
    return np.stack([body.phenotype_map.from_betas(b) for b in betas])


FAST_KEYS = ("height_cm", "mass_kg", "chest_cm", "hip_cm")


def _measure(body, betas: np.ndarray) -> dict:
    """Height and mass of the mesh exactly as ``body.measure`` gives them (top minus bottom vertex;
    volume x density), chest and hip from the body's girth regression (within ~1 cm of the mesh
    slices, tests/test_shape_from_text.py): milliseconds for a set, not minutes."""
    from ..body.shape_from_measurements import fast_measure, girth_regression

    m = fast_measure(body, np.nan_to_num(betas), FAST_KEYS, girth_regression(body))
    return {k: m[:, i] for i, k in enumerate(FAST_KEYS)}


def eval_shape_words(path: str = "auto", texts: int = 200, seed: int = 0, model_dir=None, seeds: int = 0,
                     examples: int = 3, no_shape: bool = True) -> dict:
    """The issue-#25 numbers on ``texts`` generated texts per set (see the module docstring).
    ``no_shape``: also the prompts without a shape text (the [BETA] head's reading: needs the model);
    ``seeds`` > 0: generate the first of them with that many seeds (the full model)."""
    if not 1 <= int(texts) <= 5000:
        raise ShapeMoveError(f"--texts must be between 1 and 5000, got {texts}")
    rd = _Reader(path, model_dir)
    body, names = rd.body, rd.body.phenotype_map.names
    gi, ai, mi = names.index("gender"), names.index("age"), names.index("muscle")
    res: dict = {"path": path, "texts": int(texts), "seed": int(seed)}

    # gender, and the same text with the other noun
    g = gender_texts(int(texts), seed)
    b1, ok1 = rd.betas([x["text"] for x in g])
    b2, ok2 = rd.betas([x["swapped"] for x in g])
    p1 = _readback(body, np.nan_to_num(b1))
    fem = np.array([x["female"] for x in g])
    right = ok1 & np.where(fem, p1[:, gi] >= 0.75, p1[:, gi] <= 0.25)
    m1, m2 = _measure(body, b1), _measure(body, b2)
    both = ok1 & ok2
    woman_minus_man = {k: np.where(fem, m1[k] - m2[k], m2[k] - m1[k])[both] for k in ("chest_cm", "hip_cm")}
    shape = (woman_minus_man["hip_cm"] - woman_minus_man["chest_cm"])  # hips gain on the chest in the woman
    res["gender"] = {"texts": len(g), "right_pct": 100 * float(right.mean()),
                     "men_right_pct": 100 * float(right[~fem].mean()), "women_right_pct": 100 * float(right[fem].mean()),
                     "pairs": int(both.sum()),
                     "woman_minus_man_chest_cm": float(woman_minus_man["chest_cm"].mean()),
                     "woman_minus_man_hip_cm": float(woman_minus_man["hip_cm"].mean()),
                     "hip_minus_chest_shift_cm": float(shape.mean()) if len(shape) else None,
                     "visible_pct": 100 * float((np.abs(woman_minus_man["chest_cm"]) + np.abs(woman_minus_man["hip_cm"])
                                                 >= 4.0).mean()) if len(shape) else None,
                     "examples": [{"text": x["text"], "gender": float(p1[i, gi]), "chest_cm": float(m1["chest_cm"][i]),
                                   "hip_cm": float(m1["hip_cm"][i]), "swapped": x["swapped"],
                                   "swapped_chest_cm": float(m2["chest_cm"][i]), "swapped_hip_cm": float(m2["hip_cm"][i])}
                                  for i, x in enumerate(g[:examples])]}

    # age
    a = age_texts(int(texts), seed)
    ba, oka = rd.betas([x["text"] for x in a])
    pa = _readback(body, np.nan_to_num(ba))
    lo, hi = np.array([x["lo"] for x in a]), np.array([x["hi"] for x in a])
    in_band = oka & (pa[:, ai] >= lo) & (pa[:, ai] <= hi)
    res["age"] = {"texts": len(a), "in_band_pct": 100 * float(in_band.mean()),
                  "per_band": {band: {"texts": int(sel.sum()), "in_band_pct": 100 * float(in_band[sel].mean()),
                                      "mean_age": float(pa[sel, ai].mean())}
                               for band in AGE_BANDS for sel in [np.array([x["band"] == band for x in a])]},
                  "examples": [{"text": x["text"], "age": float(pa[i, ai])} for i, x in enumerate(a[:examples])]}

    # muscle
    mu = muscle_texts(int(texts), seed)
    bm, okm = rd.betas([x["text"] for x in mu])
    pm = _readback(body, np.nan_to_num(bm))
    strong = okm & (pm[:, mi] >= 0.7)
    res["muscle"] = {"texts": len(mu), "at_least_0.7_pct": 100 * float(strong.mean()),
                     "mean_muscle": float(pm[okm, mi].mean()) if okm.any() else None,
                     "examples": [{"text": x["text"], "muscle": float(pm[i, mi])} for i, x in enumerate(mu[:examples])]}

    # numbers
    nu = numeric_texts(int(texts), seed)
    bn, okn = rd.betas([x["text"] for x in nu])
    mn = _measure(body, bn)
    dh = np.abs(mn["height_cm"] - np.array([x["height_cm"] for x in nu]))
    dm = np.abs(mn["mass_kg"] - np.array([x["mass_kg"] for x in nu]))
    met = okn & (dh <= 1.0) & (dm <= 2.0)
    res["numeric"] = {"texts": len(nu), "both_met_pct": 100 * float(met.mean()), "refused": int((~okn).sum()),
                      "height_err_cm_mean": float(dh[okn].mean()) if okn.any() else None,
                      "height_err_cm_max": float(dh[okn].max()) if okn.any() else None,
                      "mass_err_kg_mean": float(dm[okn].mean()) if okn.any() else None,
                      "mass_err_kg_max": float(dm[okn].max()) if okn.any() else None,
                      "examples": [{"text": x["text"], "stated_cm": x["height_cm"], "stated_kg": x["mass_kg"],
                                    "height_cm": float(mn["height_cm"][i]), "mass_kg": float(mn["mass_kg"][i])}
                                   for i, x in enumerate(nu[:examples])]}
    res["refused"] = [{"text": t, "error": e} for t, e in rd.refused[:20]]
    res["refused_total"] = len(rd.refused)
    res["left_to_head"] = rd.free
    res["no_shape"] = _no_shape(rd, seeds) if no_shape else {"skipped": "not asked for"}
    return res


def _no_shape(rd: _Reader, seeds: int) -> dict:
    """Prompts with no shape text: the body against the average adult (default sliders, betas 0)."""
    from ..body.measure import measure

    body = rd.body
    avg = measure(body, np.zeros(body.num_betas, np.float32))
    out: dict = {"average": {k: avg[k] for k in ("height_cm", "mass_kg", "bmi")}}
    try:
        hb = rd.head([None] * len(NO_SHAPE_PROMPTS), captions=NO_SHAPE_PROMPTS)
    except ShapeMoveError as exc:
        return {**out, "skipped": str(exc)}
    m = _measure(body, hb)
    p = _readback(body, hb)
    names = body.phenotype_map.names
    out["prompts"] = [{"prompt": t, "height_cm": float(m["height_cm"][i]), "mass_kg": float(m["mass_kg"][i]),
                       "beta_norm": float(np.linalg.norm(hb[i])),
                       **{n: float(p[i, j]) for j, n in enumerate(names)}} for i, t in enumerate(NO_SHAPE_PROMPTS)]
    if seeds > 0:
        from ..generation.generate import Generator, Request

        gen = Generator(rd.model_dir)
        per = [gen.generate_batch([Request(NO_SHAPE_PROMPTS[0], None, seconds=1.0, seed=s, candidates=1,
                                           shape_from=rd.path)])[0].betas for s in range(seeds)]
        out["seed_spread"] = float(np.abs(np.asarray(per) - per[0]).max())
    return out


def format_results(res: dict) -> str:
    g, a, m, n = res["gender"], res["age"], res["muscle"], res["numeric"]
    lines = [f"shape words on the {res['path']!r} path: {res['texts']} texts per set (seed {res['seed']}), read back "
             "through OpenBody's phenotype map; mass from the mesh volume",
             f"gender slider right (man <= 0.25, woman >= 0.75): {g['right_pct']:.1f} %  (men {g['men_right_pct']:.1f}, "
             f"women {g['women_right_pct']:.1f})",
             f"  same text, other noun ({g['pairs']} pairs): woman - man chest {g['woman_minus_man_chest_cm']:+.1f} cm, "
             f"hips {g['woman_minus_man_hip_cm']:+.1f} cm; chest+hip change >= 4 cm in {g['visible_pct']:.1f} %",
             f"age in band: {a['in_band_pct']:.1f} %  " + ", ".join(
                 f"{b} {d['in_band_pct']:.0f} % (mean {d['mean_age']:.0f} y)" for b, d in a["per_band"].items()),
             f"muscle >= 0.7: {m['at_least_0.7_pct']:.1f} %  (mean {m['mean_muscle']:.2f})",
             f"height within 1 cm and weight within 2 kg: {n['both_met_pct']:.1f} %  (mean error {n['height_err_cm_mean']:.2f} cm, "
             f"{n['mass_err_kg_mean']:.2f} kg; max {n['height_err_cm_max']:.2f} cm, {n['mass_err_kg_max']:.2f} kg; "
             f"refused {n['refused']})",
             f"texts refused (parser, or the head on its path): {res['refused_total']}; left to the [BETA] head: {res['left_to_head']}"]
    ns = res["no_shape"]
    if "prompts" in ns:
        av = ns["average"]
        lines.append(f"no shape words (average adult: {av['height_cm']:.0f} cm, {av['mass_kg']:.0f} kg):")
        for p in ns["prompts"]:
            lines.append(f"  {p['prompt']:32s} {p['height_cm']:5.1f} cm {p['mass_kg']:5.1f} kg  gender {p['gender']:.2f} "
                         f"age {p['age']:.0f}  |betas| {p['beta_norm']:.2f}")
        if "seed_spread" in ns:
            lines.append(f"  largest beta difference between seeds: {ns['seed_spread']:.2e}")
    else:
        lines.append(f"no shape words: {ns.get('skipped')}")
    for r in res["refused"][:5]:
        lines.append(f"  refused: {r['text']!r}: {r['error']}")
    return "\n".join(lines)


def add_arguments(p) -> None:
    p.add_argument("--path", choices=("auto", "head"), default="auto",
                   help="auto: the parser + fit (what generate does by default; free text goes to the head); "
                        "head: the [BETA] head reads every text (generate --shape-from head)")
    p.add_argument("--texts", type=int, default=200, help="texts per set (default 200)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--seeds", type=int, default=0,
                   help="also generate a no-shape prompt with this many seeds and compare their bodies (slow)")
    p.add_argument("--model", type=Path, default=None, help="model folder (default: the embedded default model)")
    p.add_argument("--json", type=Path, default=None, help="write the results here")


def from_cli(args) -> int:
    res = eval_shape_words(args.path, args.texts, args.seed, args.model, seeds=args.seeds)
    return show_result(format_results(res), res, args.json)
