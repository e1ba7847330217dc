"""Free text the shape-word parser does not cover, read by the `[BETA]` head alone (issue #25 part 3).

    python tools/head_words_check.py --model weights/default --model runs/head_a/model [--set blind] [--json out/head/check.json]

A small check list written for the head, kept OUT of its training texts (``beta_head_refit`` never
uses these phrases, nor the words "retired", "linebacker", "frail", "lumberjack", "ballerina",
"nurse", "stout", "burly" ...): each phrase with what a reader would expect of the body (gender
man <= 0.25 / woman >= 0.75, age band, muscle >= 0.7, weight slider high/low, height band), read back
like ``eval shape-words`` does (OpenBody's phenotype map, mass from the mesh volume). Prints one row
per phrase and model, and the share of expectations met.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT.parent))

from shapemove.core.text.shape_words import INCH, LB, ST  # noqa: E402  (the units' one definition)

# phrase -> expectations: gender "m"/"f", age (lo, hi) years, muscle >= 0.7, weight ("hi" >= 0.6 / "lo" <= 0.4),
# height_cm (lo, hi)
CHECKS = {
    "a grandmother": {"gender": "f", "age": (60, 200)},
    "a powerlifter": {"muscle": True},
    "a lanky teenage boy": {"gender": "m", "age": (0, 21), "weight": "lo", "height_cm": (176, 230)},
    "a retired nurse": {"age": (58, 200)},
    "a hulking linebacker": {"gender": "m", "muscle": True},
    "a frail old lady": {"gender": "f", "age": (65, 200), "weight": "lo"},
    "a burly lumberjack": {"gender": "m", "muscle": True},
    "a petite ballerina": {"gender": "f", "height_cm": (0, 165), "weight": "lo"},
    "a stout old man": {"gender": "m", "age": (65, 200), "weight": "hi"},
    "an overweight middle-aged dad": {"gender": "m", "age": (35, 65), "weight": "hi"},
    "a skinny schoolgirl": {"gender": "f", "age": (0, 21), "weight": "lo"},
    "my grandpa, who is ninety": {"gender": "m", "age": (70, 200)},
    "a tall basketball player": {"height_cm": (184, 230)},
    "a heavyweight boxer": {"muscle": True, "weight": "hi"},
    "a short chubby woman": {"gender": "f", "weight": "hi", "height_cm": (0, 163)},
    "a young female gymnast": {"gender": "f", "age": (0, 30)},
}
# a second list, written on 2026-11-26 BEFORE the head variants of that day (docs/design-notes.md, Bodies)
# were trained and never looked at while choosing them: its words are in no training text either
BLIND = {
    "an old fisherman": {"gender": "m", "age": (60, 200)},
    "a teenage skateboarder": {"age": (0, 21)},
    "a grandmother in her eighties": {"gender": "f", "age": (65, 200)},
    "a young mother of two": {"gender": "f", "age": (0, 35)},
    "a muscular firefighter": {"muscle": True},
    "a retired army colonel": {"age": (58, 200)},
    "a schoolboy": {"gender": "m", "age": (0, 21)},
    "a university student": {"age": (0, 30)},
    "an elderly gentleman with a cane": {"gender": "m", "age": (65, 200)},
    "a sumo wrestler": {"weight": "hi"},
    "a marathon runner": {"weight": "lo"},
    "a pregnant woman": {"gender": "f"},
    "a bearded man": {"gender": "m"},
    "a widow in her seventies": {"gender": "f", "age": (65, 200)},
    "a nephew, aged 16": {"gender": "m", "age": (0, 21)},
    "a middle-aged housewife": {"gender": "f", "age": (35, 65)},
    "the king, an old man": {"gender": "m", "age": (65, 200)},
    "a princess": {"gender": "f"},
    "a monk in his sixties": {"gender": "m", "age": (55, 200)},
    "a queen": {"gender": "f"},
    "a businesswoman": {"gender": "f"},
    "a businessman": {"gender": "m"},
    "a young soldier": {"age": (0, 30)},
    "an aging rock star": {"age": (55, 200)},
    "a female weight trainer": {"gender": "f", "muscle": True},
    "a girl of seventeen": {"gender": "f", "age": (0, 21)},
    "a lad of nineteen": {"gender": "m", "age": (0, 21)},
    "a great-grandfather": {"gender": "m", "age": (65, 200)},
    "a male model": {"gender": "m"},
    "an actress": {"gender": "f"},
    "a mighty Viking warrior": {"gender": "m", "muscle": True},
    "a lady in her nineties": {"gender": "f", "age": (65, 200)},
    "my teenage son": {"gender": "m", "age": (0, 21)},
    "my teenage daughter": {"gender": "f", "age": (0, 21)},
    "a strong woman who lifts weights": {"gender": "f", "muscle": True},
    "a tall slim woman": {"gender": "f", "weight": "lo"},
    "a short stocky man": {"gender": "m", "weight": "hi"},
    "a tall actress": {"gender": "f"},
    "a short fat grandpa": {"gender": "m", "age": (60, 200), "weight": "hi"},
    "a petite young man": {"gender": "m", "age": (0, 30)},
}
# a third list, written on 2026-11-26 after the unit reader (meets 3) was
# trained and before any head was judged on it: heights and weights in forms neither training nor
# `eval shape-words` writes ("6'1", "metres", "centimeters", "14 stone", ages and girths beside
# them). Each stated size must come out within 2 cm / 3 kg (the bar for the head).
FT, IN = 12 * INCH, INCH
NUMBERS = {
    "a man who is 6'1 and weighs 190 pounds": {"height_is": 6 * FT + IN, "mass_is": 190 * LB},
    "she's 5 foot 4, 125 lbs": {"height_is": 5 * FT + 4 * IN, "mass_is": 125 * LB},
    "tall guy, 193cm and 95kg": {"height_is": 193, "mass_is": 95},
    "weighing in at 82 kilos, 1.79 metres tall": {"height_is": 179, "mass_is": 82},
    "an old lady, 152 cm tall, 48 kg": {"height_is": 152, "mass_is": 48},
    "a 35-year-old woman, 168 cm, 61 kg": {"height_is": 168, "mass_is": 61},
    "a teenage boy, 16 years old, 5 ft 9, 140 lb": {"height_is": 5 * FT + 9 * IN, "mass_is": 140 * LB},
    "a heavy man of 120 kg": {"mass_is": 120},
    "a woman 1.62 m tall": {"height_is": 162},
    "190 centimeters, 100 kilograms": {"height_is": 190, "mass_is": 100},
    "he stands at 6 feet and weighs 14 stone": {"height_is": 6 * FT, "mass_is": 14 * ST},
    "she weighs 9 stone 7 and is 5'5\"": {"height_is": 5 * FT + 5 * IN, "mass_is": 9 * ST + 7 * LB},
    "a 28 year old male athlete, 182cm, 80kg": {"height_is": 182, "mass_is": 80},
    "5'11\", 170 lbs, 40 years old": {"height_is": 5 * FT + 11 * IN, "mass_is": 170 * LB},
    "an elderly man: height 171 cm, weight 77 kg": {"height_is": 171, "mass_is": 77},
    "a petite woman of 155 cm and 50 kg": {"height_is": 155, "mass_is": 50},
    "a 2 m tall basketball player weighing 105 kg": {"height_is": 200, "mass_is": 105},
    "a bodybuilder, 178 cm, 98 kg, waist 80 cm": {"height_is": 178, "mass_is": 98},
    "someone 165 cm tall with a 70 cm waist": {"height_is": 165},
    "a man weighing 75 kg with a 100 cm chest": {"mass_is": 75},
    "a lady of 60 kg": {"mass_is": 60},
    "6 ft 3 in, 230 lb": {"height_is": 6 * FT + 3 * IN, "mass_is": 230 * LB},
    "1.70m / 68kg": {"height_is": 170, "mass_is": 68},
    "a girl, 12 stone, 5 ft 2": {"height_is": 5 * FT + 2 * IN, "mass_is": 12 * ST},
    "a man of 185 cm who weighs 90 kilos": {"height_is": 185, "mass_is": 90},
    "a woman in her 50s, 160cm, 70kg": {"height_is": 160, "mass_is": 70},
    "my dad is 5 foot 10 and 200 pounds": {"height_is": 5 * FT + 10 * IN, "mass_is": 200 * LB},
    "an 80-year-old, 158 cm and 52 kg": {"height_is": 158, "mass_is": 52},
    "height 1.83 m, weight 88 kg": {"height_is": 183, "mass_is": 88},
    "175 cm and 11 st 2 lb": {"height_is": 175, "mass_is": 11 * ST + 2 * LB},
}
SETS = {"own": CHECKS, "blind": BLIND, "numbers": NUMBERS}
MOTION = "a person walks forward."


def read(model_dir, checks: dict = CHECKS) -> list[dict]:
    import numpy as np

    from shapemove.core.body.load import load_body_model
    from shapemove.core.body.shape_from_measurements import fast_measure
    from shapemove.core.eval.shape_eval import head_betas
    from shapemove.core.generation.model_bundle import model_files, resolve_model_dir
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    body = load_body_model(None)
    t5, reader = ShapeMoveT5.load(model_files(resolve_model_dir(model_dir))["t5"])
    texts = list(checks)
    betas = head_betas(t5, reader, [MOTION] * len(texts), texts)
    m = fast_measure(body, betas, ("height_cm", "mass_kg"))
    names = body.phenotype_map.names
    rows = []
    for i, t in enumerate(texts):
        p = dict(zip(names, body.phenotype_map.from_betas(betas[i])))
        want, ok = checks[t], {}
        if "gender" in want:
            ok["gender"] = p["gender"] <= 0.25 if want["gender"] == "m" else p["gender"] >= 0.75
        if "age" in want:
            ok["age"] = want["age"][0] <= p["age"] <= want["age"][1]
        if want.get("muscle"):
            ok["muscle"] = p["muscle"] >= 0.7
        if "weight" in want:
            ok["weight"] = p["weight"] >= 0.6 if want["weight"] == "hi" else p["weight"] <= 0.4
        if "height_is" in want:
            ok["height_is"] = abs(m[i, 0] - want["height_is"]) <= 2.0
        if "mass_is" in want:
            ok["mass_is"] = abs(m[i, 1] - want["mass_is"]) <= 3.0
        if "height_cm" in want:
            ok["height_cm"] = want["height_cm"][0] <= m[i, 0] <= want["height_cm"][1]
        rows.append({"text": t, **{k: float(v) for k, v in p.items()}, "height_cm": float(m[i, 0]),
                     "mass_kg": float(m[i, 1]), "met": {k: bool(v) for k, v in ok.items()}})
    return rows


def numeric_share(model_dir, texts: int = 200, seed: int = 0) -> dict:
    """``eval shape-words``'s numeric texts (height and weight stated) on the head path, against the
    issue's bar for the head (within 2 cm AND 3 kg) beside the eval's (1 cm and 2 kg)."""
    import numpy as np

    from shapemove.core.eval.shape_words_eval import _measure, _Reader, numeric_texts

    nu = numeric_texts(texts, seed)
    rd = _Reader("head", model_dir)
    b, _ = rd.betas([x["text"] for x in nu])
    m = _measure(rd.body, b)
    dh = np.abs(m["height_cm"] - np.array([x["height_cm"] for x in nu]))
    dm = np.abs(m["mass_kg"] - np.array([x["mass_kg"] for x in nu]))
    return {"texts": len(nu), "within_2cm_3kg_pct": 100 * float(((dh <= 2) & (dm <= 3)).mean()),
            "within_1cm_2kg_pct": 100 * float(((dh <= 1) & (dm <= 2)).mean()),
            "height_within_2cm_pct": 100 * float((dh <= 2).mean()), "mass_within_3kg_pct": 100 * float((dm <= 3).mean()),
            "height_err_cm_median": float(np.median(dh)), "mass_err_kg_median": float(np.median(dm))}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", action="append", type=Path, required=True, help="model folder (repeat to compare)")
    ap.add_argument("--set", choices=sorted(SETS), default="own",
                    help="own: the first list; blind: a list never used to choose a head; "
                         "numbers: sizes stated in forms no training text uses, each within 2 cm / 3 kg")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()
    import torch

    torch.set_num_threads(1)
    res = {}
    for md in args.model:
        rows = read(md, SETS[args.set])
        num = numeric_share(md)
        res[str(md)] = {"phrases": rows, "numeric": num}
        met = [v for r in rows for v in r["met"].values()]
        print(f"\n{md}: {sum(met)}/{len(met)} expectations met")
        for r in rows:
            miss = [k for k, v in r["met"].items() if not v]
            print(f"  {r['text']:34s} gender {r['gender']:.2f} age {r['age']:4.0f} muscle {r['muscle']:.2f} "
                  f"weight {r['weight']:.2f} {r['height_cm']:5.1f} cm {r['mass_kg']:5.1f} kg"
                  + (f"   MISSED {', '.join(miss)}" if miss else ""))
        print(f"  eval shape-words numeric texts: {num['within_2cm_3kg_pct']:.1f} % within 2 cm and 3 kg "
              f"(height {num['height_within_2cm_pct']:.1f} %, weight {num['mass_within_3kg_pct']:.1f} %; median error "
              f"{num['height_err_cm_median']:.2f} cm, {num['mass_err_kg_median']:.2f} kg), "
              f"{num['within_1cm_2kg_pct']:.1f} % within 1 cm and 2 kg")
    if args.json:
        from shapemove.core.atomic import atomic_write_json

        atomic_write_json(args.json, res)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
