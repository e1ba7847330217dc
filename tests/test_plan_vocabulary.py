"""One vocabulary, one reader: every word class of ``core/plan/vocabulary.py`` read on its example,
and no module outside ``core/plan`` that applies a regular expression to a prompt."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from shapemove.core.plan.plan import read_plan
from shapemove.core.plan.vocabulary import WORD_CLASSES
from shapemove.core.plan.words import read_words

ROOT = Path(__file__).resolve().parents[1]

# modules outside core/plan that may use ``re``: each reads some other text than a prompt
OTHER_TEXTS = {
    "core/text/shape_words.py": "the body's shape text",
    "core/models/text_numbers.py": "numbers of the shape text for the [BETA] head",
    "core/body/shape_from_measurements.py": "measurements of the shape text",
    "core/body/smpl_family.py": "body model file names",
    "core/data/actions.py": "the action patterns of captions, labels and prompts (the plan's action words)",
    "core/data/captions.py": "captions of the training data",
    "core/data/compose.py": "captions of the training data",
    "core/data/mirror.py": "captions of mirrored training clips",
    "core/data/motion_library.py": "captions of the motion library",
    "core/data/shape_text.py": "shape captions of the training data",
    "core/data/sources.py": "labels of mocap sources",
    "core/eval/part_judge_accuracy.py": "labels of mocap sources",
    "core/io/asf_amc.py": "ASF/AMC mocap files",
    "core/io/skeleton_match.py": "joint names of mocap files",
    "core/worker/client.py": "the worker's output lines",
    "core/worker/protocol.py": "the worker's JSON messages",
    "core/batch/items.py": "file names of a batch's outputs",
    "core/batch/shard.py": "the --shard option",
    "shapemove_addon/paths.py": "file names",
}


def _uses_re(path: Path) -> bool:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(a.name == "re" or a.name.startswith("re.") for a in node.names):
            return True
        if isinstance(node, ast.ImportFrom) and node.module in ("re", "regex"):
            return True
    return False


def test_only_core_plan_matches_regular_expressions_on_a_prompt():
    found = set()
    for top in ("core", "cli", "shapemove_addon"):
        for path in (ROOT / top).rglob("*.py"):
            rel = path.relative_to(ROOT).as_posix()
            if rel.startswith("core/plan/") or not _uses_re(path):
                continue
            found.add(rel)
    readers = sorted(found - set(OTHER_TEXTS))
    assert not readers, f"modules outside core/plan use regular expressions (on a prompt?): {readers}"
    assert "core/generation/generate.py" not in found and "core/generation/course_walk.py" not in found


@pytest.mark.parametrize("word_class", WORD_CLASSES, ids=[w.name for w in WORD_CLASSES])
def test_each_word_class_reads_its_example(word_class):
    if word_class.name == "order":
        assert len(read_plan(word_class.example).segments) == word_class.expect["segments"]
        return
    said = read_words(word_class.example).understood()
    for key, value in word_class.expect.items():
        assert said.get(key) == value, (word_class.example, said)


def test_words_no_class_takes_are_named():
    assert read_words("a man paces impatiently").unused == ("impatiently",)
    assert read_words("a man paces nervously").unused == () and read_words("a man paces nervously").manner == "timid"
    assert read_words("a man sits down quickly").unused == ("quickly",)   # no gait: a fast pace is not acted on
    assert read_words("an old man sits down slowly").unused == ()           # an action done slowly
    assert read_words("an old man sits down slowly").slowly and not read_words("a woman walks slowly").slowly
    assert read_words("a woman walks slowly").unused == ()
    assert read_words("a tall man walks forward").unused == ()                # the body's words are the body's


def test_the_typed_reading_is_what_the_generator_acts_on():
    w = read_words("a man walks 3 metres forward and stops")
    assert (w.stop, w.distance_m, w.travel.forward, w.gait_text) == (True, 3.0, 1, "a man walks forward")
    w = read_words("a woman jogs in a figure eight clockwise")
    assert (w.course, w.course_right, w.straight_text) == ("walk in a figure eight", True, "a woman jogs")
    assert read_words("someone turns around to the right").turn == pytest.approx(-3.14159, abs=1e-4)
    assert read_words("he jumps three times").count == ("jump", 3)
    assert read_words("a person jogs slowly").slow_flight and read_words("a person walks slowly").slow_steps


@pytest.mark.parametrize("text, seconds", [
    ("a person jogs for ten seconds", 10.0),
    ("a man walks for 8 seconds", 8.0),
    ("she runs for half a minute", 30.0),
    ("he dances for about a minute", 60.0),
    ("a 10-second jog forward", 10.0),
    ("someone waves for 2.5 s", 2.5),
    ("jumps for a few seconds", 3.0),
    ("a woman runs for 2 minutes", 60.0),        # the most a motion lasts
    ("a man walks for a while", None),           # no length
    ("walks 10 m in 5 seconds", None),           # a pace, not a length
    ("a man walks for 5 metres", None),
])
def test_the_length_the_words_ask(text, seconds):
    w = read_words(text)
    assert w.seconds == seconds
    assert ("seconds" not in w.unused and "minute" not in w.unused) or seconds is None


def test_the_words_length_sets_the_motion_and_its_segments():
    """A single segment asks its length of the generator; in a sequence each segment that says one
    is that long, the others ``SEGMENT_SECONDS``; a length given outright shares out as before, and
    the option says it won."""
    from shapemove.core.plan.option_conflicts import option_notes
    from shapemove.core.plan.plan import plan_to_json
    from shapemove.core.plan.segments import SEGMENT_SECONDS

    one = read_plan("a person jogs for ten seconds")
    assert plan_to_json(one)["segments"][0]["seconds"] == 10.0
    two = read_plan("a man jogs for 6 seconds, then waves for 2 seconds, then bows")
    assert two.lengths(None) == [6.0, 2.0, SEGMENT_SECONDS]
    assert two.lengths(9.0) == [3.0, 3.0, 3.0]
    assert option_notes("a man jogs for 6 seconds", seconds=4.0) == [
        "--seconds 4 won over the 6 s the words ask (leave out --seconds for theirs)"]
    assert option_notes("a man jogs for 6 seconds", seconds=6.0) == []
    assert option_notes("a man jogs", seconds=4.0) == []
    assert option_notes("a man jogs for 6 seconds", loop=True)[0].startswith("--loop won over the 6 s the words ask")
