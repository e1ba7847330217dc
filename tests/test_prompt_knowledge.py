"""What the model knows: the training captions/actions stored with the T5, warnings for prompts far
from all of them (command line, worker result), refusal of unreadable text and impossible numbers."""
import json

import pytest

from shapemove.core.errors import ShapeMoveError
from tiny_models import tiny_bundle  # noqa: F401  (session fixture)


@pytest.fixture(scope="module")
def gen(tiny_bundle):  # noqa: F811
    from shapemove.core.generation.generate import Generator

    return Generator(tiny_bundle[0], ik_refine_iters=0)


def test_model_folder_lists_its_captions_and_actions(tiny_bundle, gen):  # noqa: F811
    from shapemove.core.generation.model_bundle import known_actions
    from shapemove.core.train.motion_dataset import read_split

    model, data = tiny_bundle
    doc = json.loads((model / "t5" / "known_texts.json").read_text())
    captions = {c for cid in read_split(data, "train") for c in (data / "texts" / f"{cid}.txt").read_text().splitlines() if c}
    from shapemove.core.data.paraphrase_bank import known_sentences

    bank = {s for a, _ in doc["actions"] for s in known_sentences(a)}
    assert set(doc["captions"]) == captions | bank  # the training captions + 40 bank sentences per action
    acts = dict(zip(doc["captions"], doc["caption_actions"]))
    assert all(acts[s] for s in bank - captions)  # a bank sentence is listed under an action
    assert gen.known_actions and gen.known_actions == known_actions(model)
    assert "walk" in gen.known_actions and "kick" in gen.known_actions


def test_far_prompt_warns_and_names_the_closest_actions(gen, tiny_bundle):  # noqa: F811
    model, data = tiny_bundle
    caption = gen.known.captions[0]
    near = gen.check_text(caption)
    assert near.similarity > 0.99 and near.warning is None and near.nearest_caption == caption
    far = gen.check_text("A chef chops onions in a busy kitchen.")
    assert far.similarity < 0.4 and far.warning and "closest known actions" in far.warning
    assert far.nearest_actions and set(far.nearest_actions) <= set(gen.known_actions)
    kick = gen.check_text("someone kicks a football hard")
    assert kick.nearest_actions[0] == "kick", kick
    motion = gen.generate("A chef chops onions in a busy kitchen.", seconds=1.0)
    assert motion.warnings == [far.warning]
    assert gen.generate(caption, seconds=1.0).warnings == []


def test_unreadable_text_and_impossible_numbers_are_refused(gen):
    with pytest.raises(ShapeMoveError, match="mostly characters the text encoder does not know"):
        gen.generate("\u0e1c\u0e39\u0e49\u0e0a\u0e32\u0e22\u0e40\u0e14\u0e34\u0e19 \u26bd", seconds=1.0)  # Thai + emoji
    for shape, match in (("5000 cm tall", "no person is 5000 cm tall"), ("waist 0 cm", "outside"),
                         ("-170 cm tall", "negative")):
        with pytest.raises(ShapeMoveError, match=match):
            gen.generate("a person walks", shape_text=shape, seconds=1.0)


def test_cli_prints_the_warning(tiny_bundle, tmp_path, capsys):  # noqa: F811
    from shapemove.cli import main

    assert main(["generate", "--prompt", "A chef chops onions in a busy kitchen.", "--seconds", "1",
                 "--model", str(tiny_bundle[0]), "--out", str(tmp_path / "m.npz")]) == 0
    err = capsys.readouterr().err
    assert "warning: nothing like" in err and "closest known actions" in err
