"""configs/heldout_paraphrases.json: >= 100 prompts in phrasings the caption augmentation never
writes, each with its expected canonical action."""
import json
import re
from pathlib import Path

import pytest

from shapemove.core.data import captions as cap
from shapemove.core.data.actions import ACTIONS
from shapemove.core.data.sources import discover

PATH = Path(__file__).resolve().parents[1] / "configs" / "heldout_paraphrases.json"
HELD = json.loads(PATH.read_text())
REQUIRED = {"punch", "kick", "walk", "run", "jog", "jump", "wave", "squat", "sit", "cartwheel", "walk in a circle",
            "dance", "crawl", "backflip", "roll", "get up", "lie down", "kick ball", "spin kick", "bow"}
COMPOSE_CONNECTORS = (", then ", " and then ", " before ", "and after that", "first ")


def norm(s: str) -> str:
    return re.sub(r"\s+", " ", re.sub(r"[^a-z0-9' ]+", " ", s.lower())).strip()


def test_set_size_actions_and_coverage():
    prompts = HELD["prompts"]
    assert len(prompts) >= 100
    texts = [p["text"] for p in prompts] + [c["text"] for c in HELD["compositions"]]
    assert len({norm(t) for t in texts}) == len(texts)                       # no duplicates
    for p in prompts:
        assert p["action"] in ACTIONS and set(p.get("also", [])) <= set(ACTIONS) and p["action"] not in p.get("also", [])
    for c in HELD["compositions"]:
        assert len(c["sequence"]) == 2 and set(c["sequence"]) <= set(ACTIONS)
    actions = {p["action"] for p in prompts}
    assert REQUIRED <= actions and len(actions) >= 45
    # at least two prompts for every required action
    assert all(sum(p["action"] == a for p in prompts) >= 2 for a in REQUIRED)


def test_sentence_shapes_differ_from_the_generator():
    for text in [p["text"] for p in HELD["prompts"]] + [c["text"] for c in HELD["compositions"]]:
        low = text.lower()
        assert not low.startswith(tuple(s + " " for s in cap.SUBJECTS)), text       # generator subjects
        assert not re.match(r"^(a|an|the) [a-z-]+ person ", low), text                # "a happy person ..."
    for c in HELD["compositions"]:
        assert not any(k in c["text"].lower() for k in COMPOSE_CONNECTORS), c["text"]


def _generator_space() -> set:
    """Every sentence the per-source tables can produce (all subjects, shapes and styles)."""
    out = set()
    for vps in cap.BANDAI_CONTENT.values():
        for subj, manners in cap.BANDAI_STYLE.values():
            for group in cap.sentences(vps, manners, subj):
                out.update(group)
    tables = list(cap.HDM05_CLASSES.values()) + list(cap.DEEPMIMIC_MOTIONS.values())
    tables += [list(a.phrases) for a in ACTIONS.values()]
    for vps in tables:
        for group in cap.sentences(vps, []) + cap.sentences(vps, list(cap.CMU_STYLES.values())):
            out.update(group)
    return {norm(s) for s in out}


def test_no_held_out_prompt_is_a_generated_caption(mocap_root):
    generated = _generator_space()
    for clip in discover(Path(mocap_root)):
        generated.update(norm(c) for c in clip.captions)                   # incl. KIT-ML sentences
    assert len(generated) > 5000
    held = [p["text"] for p in HELD["prompts"]] + [c["text"] for c in HELD["compositions"]]
    clash = [t for t in held if norm(t) in generated]
    assert clash == []


@pytest.mark.parametrize("probe", ["A person walks forward.", "Someone is waving with the left hand."])
def test_the_clash_check_would_catch_a_generated_sentence(probe):
    assert norm(probe) in _generator_space()


@pytest.mark.parametrize("name, earlier", [
    ("heldout_paraphrases_blind.json", ["heldout_paraphrases.json"]),
    ("heldout_paraphrases_blind2.json", ["heldout_paraphrases.json", "heldout_paraphrases_blind.json"]),
])
def test_blind_sets_load_name_known_actions_and_share_no_prompt_with_the_earlier_sets(name, earlier):
    """configs/heldout_paraphrases_blind*.json: sets written blind by other authors (the second one
    seeing only the action names and how many prompts of each)."""
    from shapemove.core.eval.paraphrase_eval import load_prompts

    blind = load_prompts(PATH.with_name(name))
    assert len(blind) >= 150
    unknown = sorted({n for p in blind for n in [p["action"], *p["also"]] if n not in ACTIONS})
    assert not unknown, f"unknown action names: {unknown}"
    assert len({p["action"] for p in blind}) >= 45
    for other in earlier:
        seen = {p["text"].strip().lower() for p in load_prompts(PATH.with_name(other))}
        shared = sum(p["text"].strip().lower() in seen for p in blind)
        assert shared == 0, f"{shared} prompts of {name} repeat a prompt of {other}"


def test_no_second_blind_prompt_is_a_generated_caption(mocap_root):
    from shapemove.core.eval.paraphrase_eval import load_prompts

    generated = _generator_space()
    for clip in discover(Path(mocap_root)):
        generated.update(norm(c) for c in clip.captions)
    clash = sum(norm(p["text"]) in generated for p in load_prompts(PATH.with_name("heldout_paraphrases_blind2.json")))
    assert clash == 0, f"{clash} prompts of the second blind set are sentences the captions write"
