"""configs/heldout_sides.json and configs/heldout_two_things.json: balanced, built only from the
held-out pairs, and no prompt is a sentence the training captions can hold (captions.py,
compose_parts.parts_captions, paraphrase_bank.py, the archives' own captions)."""
import random
import re
from pathlib import Path

import pytest

from shapemove.core.data import captions as cap
from shapemove.core.data import paraphrase_bank as bank
from shapemove.core.data.actions import ACTIONS
from shapemove.core.data.compose_parts import ARMS_ACTIONS, HELD_OUT_PAIRS, LEGS_ACTIONS, parts_captions
from shapemove.core.data.mirror import swap_sides
from shapemove.core.data.sources import discover
from shapemove.core.errors import ShapeMoveError
from shapemove.core.eval.parts_eval import load_sides, load_two_things

SIDES = load_sides()
TWO = load_two_things()
TEXTS = [p["text"] for p in SIDES] + [p["text"] for p in TWO]


def norm(s: str) -> str:
    return re.sub(r"\s+", " ", re.sub(r"[^a-z0-9' ]+", " ", s.lower())).strip()


def test_sides_are_balanced():
    assert len(SIDES) >= 30
    for key, values in (("side", ("left", "right")), ("part", ("hand", "foot"))):
        counts = [sum(p[key] == v for p in SIDES) for v in values]
        assert counts[0] == counts[1], (key, counts)
    for part in ("hand", "foot"):
        assert sum(p["part"] == part and p["side"] == "left" for p in SIDES) == \
            sum(p["part"] == part and p["side"] == "right" for p in SIDES)
    for p in SIDES:  # the prompt names its side, and only that side
        words = set(norm(p["text"]).split())
        assert p["side"] in words and ({"left", "right"} - {p["side"]}).isdisjoint(words), p["text"]


def test_two_things_use_only_held_out_pairs_each_several_times():
    assert len(TWO) >= 30
    pairs = [(p["legs"], p["arms"]) for p in TWO]
    assert set(pairs) == set(HELD_OUT_PAIRS)
    assert min(pairs.count(x) for x in HELD_OUT_PAIRS) >= 3
    assert all(p["legs"] in LEGS_ACTIONS and p["arms"] in ARMS_ACTIONS for p in TWO)


def test_no_duplicates_and_no_generator_subject():
    assert len({norm(t) for t in TEXTS}) == len(TEXTS)
    subjects = tuple(s + " " for s in set(cap.SUBJECTS) | set(bank.SUBJECTS))
    for t in TEXTS:
        assert not t.lower().startswith(subjects), t
        assert not re.match(r"^(make|have|let|get|show|animate|generate|a clip of|an animation of) ", t.lower()), t


def bank_space(action: str) -> set:
    """Every sentence ``paraphrase_bank.sentence`` can write for ``action`` (all its shapes, subjects,
    phrasings); ``test_bank_space_holds_every_sampled_sentence`` keeps this in step with the bank."""
    e = bank.BANK.get(action) or {"vps": list(ACTIONS[action].phrases), "nouns": [], "agents": []}
    subjects = list(bank.SUBJECTS) + list(e["agents"])
    out = set()
    for vp in e["vps"]:
        ing, base = cap.progressive(vp), bank._base_vp(vp)
        out.add(f"{base}.")
        for subj in subjects:
            out.update({f"{subj} {vp}.", f"{subj} is {ing}.", f"{subj} {ing}."})
            out.update(f"{lead} {subj} {ing}." for lead in ("show", "animate", "generate", "a clip of", "an animation of"))
        for lead in ("make", "have", "let", "get"):
            out.update(f"{lead} {obj} {'to ' if lead == 'get' else ''}{base}." for obj in bank.OBJECTS)
    for noun in e["nouns"]:
        out.add(f"{noun}.")
        out.update(f"{subj} {verb} {noun}." for subj in subjects for verb in ("does", "performs", "shows"))
    return {cap._tidy(x) for x in out}


def training_space() -> set:
    """Sentences the caption writers can produce: every per-source table sentence (all subjects, styles,
    shapes), every legs-and-arms composition caption of the tables' verb phrases, every paraphrase
    bank sentence; each also mirrored (left <-> right)."""
    out = set()
    for vps in cap.BANDAI_CONTENT.values():
        for subj, manners in cap.BANDAI_STYLE.values():
            for group in cap.sentences(vps, manners, subj):
                out.update(group)
    tables = list(cap.HDM05_CLASSES.values()) + list(cap.DEEPMIMIC_MOTIONS.values())
    tables += [list(a.phrases) for a in ACTIONS.values()]
    for vps in tables:
        for group in cap.sentences(vps, []):
            out.update(group)
    legs_vps = {vp for a in LEGS_ACTIONS for vp in ACTIONS[a].phrases}
    legs_vps |= {vp for k, vps in cap.BANDAI_CONTENT.items() if k.startswith(("walk", "run")) for vp in vps}
    legs_vps |= set(cap.HDM05_CLASSES["jogLeftCircle"] + cap.HDM05_CLASSES["sneak"])
    arms_vps = {vp for a in ARMS_ACTIONS for vp in ACTIONS[a].phrases}
    arms_vps |= {vp for k in ("bye", "byebye", "guide", "respond", "call", "punch", "slash", "wave-both-hands",
                              "wave-left-hand", "wave-right-hand", "raise-up-both-hands", "raise-up-left-hand",
                              "raise-up-right-hand") for vp in cap.BANDAI_CONTENT[k]}
    arms_vps |= set(cap.HDM05_CLASSES["grabHighR"] + cap.HDM05_CLASSES["rotateArmsBothBackward"]
                    + cap.HDM05_CLASSES["throwBasketball"])
    for x in sorted(legs_vps):
        for y in sorted(arms_vps):
            out.update(parts_captions(f"{x}|{y}", x, y, n=1000))
    for a in ACTIONS:
        out |= bank_space(a)
    return {norm(s) for s in out} | {norm(swap_sides(s)) for s in out}


def test_bank_space_holds_every_sampled_sentence():
    rng = random.Random(0)
    for a in ("walk", "jog", "wave", "raise hand", "kick", "punch", "sidestep"):
        space = bank_space(a)
        missing = {s for s in (bank.sentence(a, rng) for _ in range(300)) if s not in space}
        assert missing == set(), (a, sorted(missing)[:3])


@pytest.fixture(scope="module")
def space():
    return training_space()


def test_no_held_out_prompt_is_a_training_caption(space):
    assert len(space) > 100000
    assert [t for t in TEXTS if norm(t) in space] == []


def test_no_held_out_prompt_is_a_caption_of_the_archives(mocap_root):
    archive = {norm(c) for clip in discover(Path(mocap_root)) for c in clip.captions}   # incl. KIT-ML sentences
    assert len(archive) > 1000
    assert [t for t in TEXTS if norm(t) in archive] == []


@pytest.mark.parametrize("probe", ["A person raises the left hand.", "Someone is waving with the right hand.",
                                   "A woman waves as she walks.", "A man jogs forward while raising a hand."])
def test_the_check_would_catch_a_training_caption(space, probe):
    assert norm(probe) in space


def test_bad_prompt_files(tmp_path):
    (tmp_path / "s.json").write_text('{"prompts": [{"text": "Raise the left hand.", "side": "up", "part": "hand"}]}')
    with pytest.raises(ShapeMoveError, match="prompt 0 must be"):
        load_sides(tmp_path / "s.json")
    (tmp_path / "t.json").write_text('{"prompts": [{"text": "Walk and wave.", "legs": "walk", "arms": "wave"}]}')
    with pytest.raises(ShapeMoveError, match="not one of the held-out pairs"):
        load_two_things(tmp_path / "t.json")
    (tmp_path / "e.json").write_text('{"prompts": []}')
    with pytest.raises(ShapeMoveError, match="no prompts"):
        load_two_things(tmp_path / "e.json")
    with pytest.raises(ShapeMoveError, match="not found"):
        load_sides(tmp_path / "missing.json")


def test_the_tuning_set_holds_trained_pairs_only_and_says_so(tmp_path):
    """configs/tuning_two_things.json may pair what training composes (it is marked "tuning"); the
    held-out set may not, and the two share no pair and no prompt."""
    import json

    tune = load_two_things(Path(__file__).resolve().parents[1] / "configs" / "tuning_two_things.json")
    assert len(tune) == 32 and all(t["tuning"] for t in tune) and not any(t["tuning"] for t in TWO)
    assert not {(t["legs"], t["arms"]) for t in tune} & HELD_OUT_PAIRS
    assert not {t["text"].lower() for t in tune} & {t["text"].lower() for t in TWO}
    p = tmp_path / "trained.json"
    p.write_text(json.dumps({"prompts": [{"text": "a man walks and waves", "legs": "walk", "arms": "wave"}]}))
    with pytest.raises(ShapeMoveError, match="held-out pairs"):
        load_two_things(p)
    p.write_text(json.dumps({"tuning": True, "prompts": [{"text": "a man walks and waves", "legs": "walk",
                                                          "arms": "wave"}]}))
    assert load_two_things(p)[0]["tuning"] is True


def test_a_tuning_sides_set_is_balanced_and_apart_from_the_held_out_one():
    """configs/tuning_sides.json is marked "tuning", balanced like the held-out set, and shares no
    prompt with it; a tuning two-things run judges it instead of the held-out sides."""
    from shapemove.core.eval.parts_eval import TUNING_SIDES

    tune = load_sides(TUNING_SIDES)
    assert len(tune) == 32 and all(t["tuning"] for t in tune) and not any(t["tuning"] for t in SIDES)
    for key, values in (("side", ("left", "right")), ("part", ("hand", "foot"))):
        assert [sum(p[key] == v for p in tune) for v in values] == [16, 16], key
    for p in tune:
        words = set(norm(p["text"]).split())
        assert p["side"] in words and ({"left", "right"} - {p["side"]}).isdisjoint(words), p["text"]
    assert not {norm(t["text"]) for t in tune} & {norm(t["text"]) for t in SIDES}
    from shapemove.core.eval.parts_eval import sides_beside

    tuning_two = load_two_things(Path(__file__).resolve().parents[1] / "configs" / "tuning_two_things.json")
    assert sides_beside(None, tuning_two) == TUNING_SIDES and sides_beside(None, TWO) is None
    assert sides_beside("mine.json", tuning_two) == "mine.json"             # a file named wins
