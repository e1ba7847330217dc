"""A prompt's ordered segments (core/plan/segments.py), what the readers understand of each
(core/plan/reading.py), the notes of an option that overrides the words
(core/plan/option_conflicts.py) and `generate --explain` (no model loaded)."""
import json

import numpy as np
import pytest

from shapemove.cli import main
from shapemove.core.plan.explain import plan_json, plan_lines
from shapemove.core.plan.option_conflicts import option_notes
from shapemove.core.plan.reading import understood
from shapemove.core.plan.plan import read_plan
from shapemove.core.plan.segments import SEGMENT_SECONDS, split_segments


@pytest.mark.parametrize("prompt, segments", [
    ("a person walks forward, then sits down", ["a person walks forward", "a person sits down"]),
    ("after waving, she jogs", ["she is waving", "she jogs"]),
    ("a man jogs and then waves", ["a man jogs", "a man waves"]),
    ("before sitting down he waves", ["he waves", "he is sitting down"]),
    ("she jogs after waving", ["she is waving", "she jogs"]),
    # a "before" / "after" clause of an action orders a clause of a motion no take is of
    ("before sitting down, he glances back", ["he glances back", "he is sitting down"]),
    ("she glances back before sprinting off", ["she glances back", "she is sprinting off"]),
    ("he stretches his neck after jumping", ["he is jumping", "he stretches his neck"]),
    ("a person waves before he sits down", ["a person waves", "he sits down"]),
    ("first a person walks forward, then turns around, then sits down",
     ["a person walks forward", "a person turns around", "a person sits down"]),
    ("she first waves, then jogs in place", ["she waves", "she jogs in place"]),
    ("he waves. then he jogs.", ["he waves", "he jogs"]),
    ("a woman walks in a circle followed by jumping twice", ["a woman walks in a circle", "a woman is jumping twice"]),
    ("stroll ahead, followed by a friendly hand wave", ["a person stroll ahead", "a person does a friendly hand wave"]),
    ("spring into the air, afterwards bowing to the judges",
     ["a person spring into the air", "a person is bowing to the judges"]),
    ("the man squats, afterwards he jumps", ["the man squats", "he jumps"]),
    ("a person sits down after walking in a circle", ["a person is walking in a circle", "a person sits down"]),
    ("someone walks up and down the room then sits", ["someone walks up and down the room", "someone sits"]),
    ("a man kicks with the left leg and then punches with the right hand",
     ["a man kicks with the left leg", "a man punches with the right hand"]),
    ("a woman runs a little and later she sits down", ["a woman runs a little", "she sits down"]),
    ("she walks, a minute later she sits", ["she walks", "she sits"]),
    ("he jogs and later on stretches", ["he jogs", "he stretches"]),
    ("someone walks backwards, after which they wave", ["someone walks backwards", "they wave"]),
    ("a boy jumps around and eventually lies down", ["a boy jumps around", "a boy lies down"]),
    ("a person squats, subsequently stands up", ["a person squats", "a person stands up"]),
    ("she jogs for a while and finishes with a bow", ["she jogs for a while", "she does a bow"]),
    ("she sprints ahead and ends by jumping forward", ["she sprints ahead", "she is jumping forward"]),
    ("after a bow, the actor walks away", ["the actor does a bow", "the actor walks away"]),
    ("after a long walk she sits down", ["she does a long walk", "she sits down"]),   # no comma: the subject cuts
    ("a man jumps and follows it with a bow", ["a man jumps", "a man does a bow"]),
    # a way alone after "then" goes on with the verb before it
    ("a man runs to the left then to the right", ["a man runs to the left", "a man runs to the right"]),
    ("she sidesteps to the right, then back to the left", ["she sidesteps to the right", "she sidesteps back to the left"]),
    ("he walks ahead, then backwards", ["he walks ahead", "he walks backwards"]),
    ("a person raises the right hand and then the left hand", ["a person raises the right hand", "a person raises the left hand"]),
    ("he waves with the left hand, then the other one", ["he waves with the left hand", "he waves the right one"]),
    # a list of steps whose last an order word starts; a turn stays with its gait, a participle is two things at once
    ("she walks ahead, spins around, then waves", ["she walks ahead", "she spins around", "she waves"]),
    ("the boy jumps, squats, then runs off", ["the boy jumps", "the boy squats", "the boy runs off"]),
    ("someone jogs forward, turns around, then walks back", ["someone jogs forward, turns around", "someone walks back"]),
    ("a woman jogs, waving, then sits down", ["a woman jogs, waving", "a woman sits down"]),
    # "and" with a change of posture on one side orders
    ("an old man gets up and walks away", ["an old man gets up", "an old man walks away"]),
    ("she walks to the chair and sits down", ["she walks to the chair", "she sits down"]),
    ("he lies down and rolls over", ["he lies down", "he rolls over"]),
    ("a man crawls, then stands up and runs", ["a man crawls", "a man stands up", "a man runs"]),
    # standing up after a squat or a bend is its own end: the segment after it is what follows the stand-up
    ("a woman squats, then stands up and waves", ["a woman squats", "a woman waves"]),
    ("she bends over, then stands up and walks away", ["she bends over", "she walks away"]),
    ("a man sits down, then stands up and waves", ["a man sits down", "a man stands up", "a man waves"]),
    ("she sits down and then waves", ["she sits down", "she waves"]),   # an order word: one after the other
    # "and" between two actions one body does not do at once orders, and so do the commas of a list before it
    ("she runs to the car and jumps in", ["she runs to the car", "she jumps in"]),
    ("a person walks up to a table and puts down a cup", ["a person walks up to a table", "a person puts down a cup"]),
    ("a man kicks and punches", ["a man kicks", "a man punches"]),
    ("she jumps, squats and waves", ["she jumps", "she squats", "she waves"]),
    ("a woman walks forward, turns around and walks back", ["a woman walks forward, turns around", "a woman walks back"]),
    ("a person squats down, subsequently stands up and runs", ["a person squats down", "a person runs"]),
    # a turn before a gait starts it (one segment); before anything else it is done first, on the spot
    ("a woman turns to the right and waves", ["a woman turns to the right", "a woman waves"]),
    ("she turns around and kicks", ["she turns around", "she kicks"]),
    # a stop between two things is the gait's own stop, then the next thing
    ("a man walks forward, stops, and waves", ["a man walks forward, then stops", "a man waves"]),
    ("she walks forward and stops and then waves", ["she walks forward, then stops", "she waves"]),
    ("he walks, stops, then turns around", ["he walks, then stops", "he turns around"]),
    ("a man runs, stops suddenly and looks around", ["a man runs, then stops", "a man looks around"]),
    # with no "and" that orders, a list of verbs of actions one after the other is cut at its commas
    ("a boy runs, jumps and lands on both feet", ["a boy runs", "a boy jumps and lands on both feet"]),
    ("a woman walks, sits down", ["a woman walks", "a woman sits down"]),
    # a turn after a gait that counts its steps or a distance comes after them
    ("the man walks 10 steps and turns left", ["the man walks 10 steps", "the man turns left"]),
    ("a man walks 3 metres and turns around", ["a man walks 3 metres", "a man turns around"]),
    ("a man walks 10 steps, turns around", ["a man walks 10 steps", "a man turns around"]),   # or a comma
    ("she walks three steps, turns left and walks on", ["she walks three steps", "she turns left", "she walks on"]),
    ("a man walks 2 metres, turns right, walks 2 metres, turns right again",   # a list of measured legs and turns
     ["a man walks 2 metres", "a man turns right", "a man walks 2 metres", "a man turns right again"]),
    ("he walks 3 steps, turns around, walks 3 steps back", ["he walks 3 steps", "he turns around", "he walks 3 steps back"]),
    # "once" opening a clause and "having" with its comma come first; a past tense names its action
    ("once she has waved, she runs off", ["she has waved", "she runs off"]),
    ("having bowed, the actor walks away", ["the actor bowed", "the actor walks away"]),
    ("having finished his run, the man waves", ["the man finished his run", "the man waves"]),
    ("the woman bows and, after that, walks off", ["the woman bows", "the woman walks off"]),
    # a person of any noun the body words know, or a role, is the subject of every segment
    ("the boxer punches, then kicks and then bows", ["the boxer punches", "the boxer kicks", "the boxer bows"]),
    ("a grandmother sits down slowly, then lies down", ["a grandmother sits down slowly", "a grandmother lies down"]),
    ("a dancer spins around, then bows", ["a dancer spins around", "a dancer bows"]),
])
def test_ordering_words_make_segments_in_the_order_they_happen(prompt, segments):
    assert split_segments(prompt) == segments
    plan = read_plan(prompt)
    assert plan.is_sequence and [s.text for s in plan.segments] == segments
    assert sum(s.share for s in plan.segments) == pytest.approx(1.0)


@pytest.mark.parametrize("prompt", [
    "a man walks back and forth", "a person walks to and fro", "someone paces up and down the room",
    "a person jogs and waves", "a dog runs after the ball", "a person walks next to the wall",
    "a person walks forward and turns around", "A woman jogs along, waving her left hand",
    "a person walks forward and then stops.", "she jogs, then comes to a stop", "a man walks 4 steps then halts",
    "a woman walks forward waving, then stops", "he runs, then he stops", "a person walks, then he",
    "a person walks then 123", "Leap up and rotate a full 360 before landing.",
    "having a good time, she dances", "once upon a time a man walked", "a man waves once while walking",
    "Sink down by bending both knees, then straighten.", "Turn sideways head over heels, hands then feet.",
    "Favoring one leg after twisting an ankle.", "Someone stretching their arms overhead after waking up",
    "the man later waves", "after the rain, he jogs", "a man walks to the end of the room",
    "she walks to the end of the hall",
    "a skater jumps and twirls in the air", "a martial artist whirls around and kicks", "the man stands and waves",
    "someone stands up and down", "he squats and stands up", "a woman walks and waves",
    "A see-you-later gesture to a friend leaving.", "she says see you later and walks away",
    "after the warm-up the man runs", "a man walks ahead, waves, and nods",
    # a gait and an arm gesture at once, a turn beside its gait
    "a man walks and throws a ball", "a man walks and turns left", "a person turns around and walks away",
    "a man walks forward, turns around", "he jogs and stops suddenly", "a person turns around, walks away",
    # the arms brought down after a raise: the raise's own end, which its takes perform
    "a woman raises her arms, then lowers them slowly", "he raises his right hand, then drops it",
    # a sit and an arm gesture at once: waving seated
    "a woman sits down and waves", "he sits and raises his hand",
    # a list without an order word: at once by body part, a squat's own standing up, the arms of a jump
    "a woman walks, waves", "he squats, stands up", "vertical jump, arms swinging up",
    # a stop that ends the prompt, a bus stop, a stop denied
    "he jogs to the corner and stops", "a man walks to the bus stops and waits", "she runs without stopping and waves",
])
def test_and_alone_courses_and_things_at_once_stay_one_segment(prompt):
    assert split_segments(prompt) == [prompt]
    assert not read_plan(prompt).is_sequence


def test_lengths_share_the_seconds_or_take_a_default_each():
    plan = read_plan("a person walks forward, then turns around, then sits down")
    assert plan.lengths(6.0) == pytest.approx([2.0, 2.0, 2.0])
    assert plan.lengths(None) == pytest.approx([SEGMENT_SECONDS] * 3)



def test_a_course_segment_takes_the_time_to_go_once_round_when_the_length_is_the_models():
    """Hand-derived from the default model's typical walk (1.194 m/s) and jog (1.831 m/s): a circle
    of 1 m walked once round at 0.9 of that pace, 2 pi / (0.9 x 1.194) = 5.85 s, jogged 3.81 s,
    which the least length makes 4 s (a figure eight, 4 pi m, jogged 7.63 s); a gait to one side
    has no round; a total asked is shared as before; without the pace, the default."""
    from shapemove.core.generation.course_shapes import model_course_seconds

    once_round = model_course_seconds(None)
    plan = read_plan("a man walks a loop around the tree, then waves")
    assert plan.lengths(None, once_round) == pytest.approx([2 * np.pi / (0.9 * 1.194), SEGMENT_SECONDS], abs=0.01)
    assert read_plan("she jogs in a circle, then sits").lengths(None, once_round)[0] == pytest.approx(4.0)
    assert read_plan("she jogs in a figure eight, then sits").lengths(None, once_round)[0] == pytest.approx(
        4 * np.pi / (0.9 * 1.831), abs=0.01)
    assert read_plan("he runs to the left, then waves").lengths(None, once_round) == pytest.approx([SEGMENT_SECONDS] * 2)
    assert plan.lengths(6.0, once_round) == pytest.approx([3.0, 3.0])
    assert plan.lengths(None) == pytest.approx([SEGMENT_SECONDS] * 2)
    shown = plan_json("a man walks a loop around the tree, then waves", course_seconds=once_round)
    assert [s["seconds"] for s in shown["segments"]] == pytest.approx([5.847, 3.0], abs=0.001)


def test_a_distance_segment_takes_the_time_to_go_it_when_the_length_is_the_models():
    """Hand-derived from the default model's typical walk (1.194 m/s) and run (2.894 m/s): "walks 5
    metres, then turns around" went 4.2 m in the 3 s a segment had; now 5 / (0.9 x 1.194) + 1 s to
    stand = 5.65 s, run 20 m 8.68 s, slowly at 0.8 of the pace; a short distance keeps the default;
    a total asked is shared as before."""
    from shapemove.core.generation.course_shapes import model_course_seconds

    at_pace = model_course_seconds(None)
    plan = read_plan("a man walks 5 metres, then turns around and walks back")
    assert plan.lengths(None, at_pace) == pytest.approx([5 / (0.9 * 1.194) + 1.0, SEGMENT_SECONDS], abs=0.01)
    assert read_plan("she runs 20 metres, then waves").lengths(None, at_pace)[0] == pytest.approx(20 / (0.9 * 2.894) + 1, abs=0.01)
    slow = read_plan("he walks 3 metres slowly, then sits down").lengths(None, at_pace)[0]
    assert slow == pytest.approx(3 / (0.9 * 1.194 * 0.8) + 1.0, abs=0.01)
    assert read_plan("he walks 1 metre, then waves").lengths(None, at_pace)[0] == SEGMENT_SECONDS
    assert plan.lengths(8.0, at_pace) == pytest.approx([4.0, 4.0])


def test_a_counted_segment_takes_as_long_as_its_repetitions_when_the_length_is_the_models():
    """"six jumping jacks, then waves": 7 x 1.1 s for the jacks (one more for the start and the end),
    the default for the wave; a total asked is shared as before; few repetitions keep the default."""
    plan = read_plan("she does six jumping jacks, then waves")
    assert plan.lengths(None) == pytest.approx([7.7, SEGMENT_SECONDS])
    assert plan.lengths(6.0) == pytest.approx([3.0, 3.0])
    assert read_plan("he squats twice, then jumps").lengths(None) == pytest.approx([4.2, SEGMENT_SECONDS])
    assert read_plan("he jumps once, then waves").lengths(None) == pytest.approx([SEGMENT_SECONDS] * 2)


def test_a_lie_down_segment_takes_the_time_a_captured_lie_down_takes():
    """5.3 s from the root's first drop to lying still (the library's lie-downs); a get-up fits the 3 s
    default; a total asked is shared as before."""
    plan = read_plan("a man lies down, then gets up")
    assert plan.lengths(None) == pytest.approx([5.3, SEGMENT_SECONDS])
    assert plan.lengths(6.0) == pytest.approx([3.0, 3.0])
    assert read_plan("she walks over and lies down on the floor").lengths(None) == pytest.approx([SEGMENT_SECONDS, 5.3])


def test_the_readings_are_the_generators():
    assert understood("a man walks 3 metres forward and stops") == {
        "actions": ["walk"], "travel": "forward", "distance_m": 3.0, "stop": True}
    assert understood("someone turns around")["turn_degrees"] == 180
    assert understood("she takes three steps and stops")["steps"] == 3
    assert understood("a person jumps twice")["count"] == 2
    assert understood("a person jogs in place")["in_place"] is True
    assert understood("he waves with the left hand")["side"] == "left hand"
    r = understood("a woman jogs in a circle clockwise and waves")
    assert (r["course"], r["course_way"], r["arms"]) == ("walk in a circle", "right", "a person waves")


def test_an_option_that_overrides_the_words_says_it_won():
    assert option_notes("a man walks in a circle") == []
    (loop,) = option_notes("a man walks in a circle", loop=True)
    assert loop.startswith("--loop won over 'in a circle'")
    assert "180 degrees" in option_notes("someone turns around", loop=True)[0]
    assert option_notes("a person walks forward, then sits down", loop=True)[0].startswith("--loop won over the order of 2")
    assert option_notes("she walks 5 metres and stops", in_place=True) == [
        "--in-place won over the distance of 5 m: the travel is removed"]
    assert option_notes("a person walks in a zigzag", path=True) == ["--path won over 'zigzag': the body walks your path"]
    assert option_notes("she jogs off to her right", path=True) == ["--path won over 'to the right': the body walks your path"]
    assert plan_lines("a man runs to the left") == ["understood: run; course: to the left, a quarter turn; left"]
    assert option_notes("a person walks forward", loop=True, in_place=True) == []


def test_explain_prints_the_plan_as_json_without_a_model(tmp_path, capsys):
    code = main(["generate", "--prompt", "after waving, she jogs in a circle", "--seconds", "4", "--loop", "--explain",
                 "--model", str(tmp_path / "no_model_here")])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert [s["text"] for s in out["segments"]] == ["she is waving", "she jogs in a circle"]
    assert [s["seconds"] for s in out["segments"]] == [2.0, 2.0]
    assert out["segments"][1]["understood"]["course"] == "walk in a circle"
    assert len(out["notes"]) == 2 and out == plan_json("after waving, she jogs in a circle", 4, loop=True)
    assert plan_json("a person waves")["segments"][0]["seconds"] is None
    whole = plan_json("a person walks forward, then sits down", 4, by_parts=False)["segments"]
    assert whole == [{"text": "a person walks forward, then sits down", "share": 1.0, "seconds": 4.0, "understood": {}}]


def test_generate_without_out_or_explain_is_one_sentence(capsys):
    assert main(["generate", "--prompt", "a person waves"]) == 2
    assert capsys.readouterr().err.startswith("error: give the motion file to write with --out")


def test_one_line_per_segment():
    assert plan_lines("a person walks forward") == ["understood: walk; forward"]
    lines = plan_lines("a person walks forward, then sits down")
    assert lines == ["understood 1 of 2 (50%): 'a person walks forward': walk; forward",
                     "understood 2 of 2 (50%): 'a person sits down': sit"]


def test_tuning_sequences_are_cut_in_order():
    """configs/tuning_sequences.json: 38 prompts in our own words that the cutting was tuned on
    ("and later", "after which", "eventually", "finishes with", "after a bow,", "follows it with",
    "after a long walk she", "to the left then to the right", "walks ahead, spins around, then"),
    all cut right."""
    from pathlib import Path

    from shapemove.core.eval.sequence_eval import load_sequences, split_right

    rows = load_sequences(Path(__file__).resolve().parents[1] / "configs" / "tuning_sequences.json")
    assert len(rows) == 38
    assert all(split_right([s.text for s in read_plan(r["text"]).segments], r["words"]) for r in rows)


def test_held_out_sequences_are_cut_in_order():
    """configs/heldout_sequences.json: 42 prompts in words never used to tune the cutting, each with a
    word each segment must hold in order: all 42 are cut right ("before crouching down, she looks
    around" was the miss while both sides of a "before" had to name an action: the rule that a
    clause saying what someone does may stand for one was written knowing it)."""
    from pathlib import Path

    rows = json.loads((Path(__file__).resolve().parents[1] / "configs" / "heldout_sequences.json").read_text())["prompts"]
    right = 0
    for prompt, want in rows:
        segments = [s.text for s in read_plan(prompt).segments]
        right += len(segments) == len(want) and all(w in s for w, s in zip(want, segments))
    assert len(rows) >= 40 and right == len(rows)
