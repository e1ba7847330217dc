"""`generate --plan PLAN.json`: the JSON `--explain` prints, edited, is read back field by field
(a wrong field is named), generated from, and kept in the motion file."""
from __future__ import annotations

import json

import pytest

from shapemove.cli import main
from shapemove.core.errors import ShapeMoveError
from shapemove.core.plan.explain import plan_json
from shapemove.core.plan.plan import plan_from_json, plan_to_json
from shapemove.core.scene.motion_file import load_motion


@pytest.mark.parametrize("prompt", ["a person walks forward, then sits down", "a man walks 3 metres forward and stops",
                                    "a woman jogs in a circle clockwise and waves", "someone kicks with the left leg",
                                    "a man jumps twice", "someone turns around to the right"])
def test_an_unedited_plan_reads_back_as_it_was_printed(prompt):
    printed = plan_json(prompt, 4)
    assert plan_to_json(plan_from_json(json.dumps(printed)))["segments"] == printed["segments"]


def test_every_plan_the_tuning_prompts_print_reads_back():
    """Every prompt of the tuning sets (and forms of each reading: raised arms kept up, both hands,
    a return, a turn beside a gait): its printed plan loads back with ``--plan`` and prints the same
    ("with both arms raised" printed ``arms_held``, which ``--plan`` refused as no field of a plan)."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "configs"
    prompts = ["a man walks with both arms raised", "a woman waves with both hands", "he raises a hand",
               "a child hops on one foot", "a boy jumps up and down", "a man jumps in place",
               "a man walks forward, then walks back",
               "a man turns around and walks away", "a person raises the right hand and then the left hand"]
    for name in ("heldout_paraphrases.json", "tuning_two_things.json", "tuning_sequences.json"):
        for p in json.loads((root / name).read_text()).get("prompts", []):
            prompts.append(p["text"] if isinstance(p, dict) else p[0])
    for row in json.loads((root / "tuning_pace.json").read_text())["rows"]:
        prompts += [v for v in (row.values() if isinstance(row, dict) else row) if isinstance(v, str) and " " in v]
    for prompt in prompts:
        printed = plan_json(prompt)
        assert plan_to_json(plan_from_json(json.dumps(printed)))["segments"] == printed["segments"], prompt


def test_edited_fields_are_what_the_plan_holds():
    edited = plan_json("a person walks forward", 4)
    edited["segments"][0]["understood"]["actions"] = ["run"]
    plan = plan_from_json(edited)
    assert plan.segments[0].text == "a person runs forward" and plan.segments[0].words.actions[0] == "run"
    edited = plan_json("a person walks forward", 4)
    edited["segments"][0]["understood"].update(course="walk in a circle", course_way="right", distance_m=5)
    w = plan_from_json(edited).segments[0].words
    assert (w.course, w.course_right, w.distance_m, w.stop) == ("walk in a circle", True, 5.0, True)
    del edited["segments"][0]["understood"]["travel"]
    assert not plan_from_json(edited).segments[0].words.travel.named   # a field removed asks nothing
    sit = plan_json("an old man sits down slowly")
    assert sit["segments"][0]["understood"]["slowly"] is True and plan_from_json(sit).segments[0].words.slowly
    del sit["segments"][0]["understood"]["slowly"]
    assert not plan_from_json(sit).segments[0].words.slowly            # taken out: played at its own speed
    squat = plan_json("a man squats and holds it")
    assert squat["segments"][0]["understood"]["held_low"] is True and plan_from_json(squat).segments[0].words.held_low
    squat["segments"][0]["understood"]["held_low"] = False
    assert not plan_from_json(squat).segments[0].words.held_low        # turned off: it stands up again


def test_actions_taken_out_of_a_plan_lose_their_words_and_actions_put_in_are_said():
    edited = plan_json("a woman stands up and waves")          # two segments: the stand-up, then the wave
    assert [s["understood"]["actions"] for s in edited["segments"]] == [["get up"], ["wave"]]
    one = {"segments": [{"text": "a woman stands up and waves", "understood": {"actions": ["wave"]}}]}
    seg = plan_from_json(one).segments[0]
    assert (seg.text, seg.words.actions) == ("a woman waves", ("wave",))
    one["segments"][0]["understood"]["actions"] = ["get up"]
    assert plan_from_json(one).segments[0].words.actions == ("get up",)
    seg = plan_from_json({"segments": [{"text": "a man kicks and punches", "understood": {"actions": ["punch"]}}]}).segments[0]
    assert (seg.text, seg.words.actions) == ("a man punches", ("punch",))
    seg = plan_from_json({"segments": [{"text": "a person walks forward",
                                        "understood": {"actions": ["walk", "wave"]}}]}).segments[0]
    assert (seg.text, seg.words.actions, seg.words.parts.arms_action) == \
        ("a person walks forward and waves", ("walk", "wave"), "wave")


@pytest.mark.parametrize("plan, field", [
    ({"segments": [{"text": "a man walks", "understood": {"course": "triangle"}}]}, "segments[0].understood.course"),
    ({"segments": [{"text": "a man walks", "seconds": 0.1}]}, "segments[0].seconds"),
    ({"segments": [{"text": "a man walks", "understood": {"count": 2}}]}, "segments[0].understood.count"),
    ({"segments": [{"text": "a man walks", "understood": {"colour": "red"}}]}, "segments[0].understood.colour"),
    ({"segments": [{"text": "a man walks", "understood": {"side": "left ear"}}]}, "segments[0].understood.side"),
    ({"segments": [{"text": "a man walks", "understood": {"actions": ["levitate"]}}]}, "segments[0].understood.actions[0]"),
    ({"segments": [{"text": "a man walks", "understood": {"steps": 3, "stop": False}}]}, "segments[0].understood.stop"),
    ({"segments": [{"text": "a man sits", "understood": {"slowly": "yes"}}]}, "segments[0].understood.slowly"),
    ({"segments": [{"text": "a man squats", "understood": {"held_low": "yes"}}]}, "segments[0].understood.held_low"),
    ({"segments": [{"text": ""}]}, "segments[0].text"),
    ({"segments": []}, "segments"),
    ({"segments": [{"text": "a man walks"}, {"text": "a man jumps", "understood": {"count": 20}}]},
     "segments[1].understood.count"),
])
def test_a_wrong_field_is_named(plan, field):
    with pytest.raises(ShapeMoveError) as err:
        plan_from_json(plan)
    assert str(err.value).startswith(f"plan: {field}: "), str(err.value)


def test_generate_from_an_edited_plan_keeps_it_in_the_motion_file(tmp_path, capsys):
    edited = plan_json("a person walks forward, then sits down", 2.5)
    edited["segments"][0]["seconds"], edited["segments"][1]["seconds"] = 1.0, 1.5
    edited["segments"][1]["understood"]["actions"] = ["wave"]
    (tmp_path / "plan.json").write_text(json.dumps(edited))
    out = tmp_path / "m.npz"
    assert main(["generate", "--plan", str(tmp_path / "plan.json"), "--candidates", "1", "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert "understood 2 of 2" in said and "wave" in said
    m = load_motion(out)
    kept = json.loads(m.plan)
    assert [s["text"] for s in kept["segments"]] == ["a person walks forward", "a person waves"]
    assert [(int(b) - int(a)) / m.fps for a, b in m.segment_bounds] == pytest.approx([1.0, 1.5], abs=0.21)
    assert main(["generate", "--plan", str(tmp_path / "nope.json"), "--out", str(out)]) != 0
    assert "plan file not found" in capsys.readouterr().err


def test_an_edited_timeline_keeps_its_edits_on_a_new_body(tmp_path):
    import numpy as np

    from shapemove.core.generation.loaded_generator import loaded_generator
    from shapemove.core.generation.track import headings

    edited = plan_json("a person walks forward, then waves", 2.5)
    edited["segments"][0]["seconds"], edited["segments"][1]["seconds"] = 1.5, 1.0
    edited["segments"][0]["understood"].update(course="walk in a circle", course_way="right")
    (tmp_path / "plan.json").write_text(json.dumps(edited))
    out = tmp_path / "m.npz"
    assert main(["generate", "--plan", str(tmp_path / "plan.json"), "--candidates", "1", "--out", str(out)]) == 0

    def turned(m) -> float:   # radians the first segment turns (+ = left)
        a, b = m.segment_bounds[0]
        h = np.unwrap(headings(m.joints))
        return float(h[b - 1] - h[a])

    m = load_motion(out)
    again = loaded_generator(None, None).redecode(m, np.r_[1.5, -1.0, np.zeros(8)].astype(np.float32))
    assert turned(m) < -3.0 and turned(again) < -3.0   # clockwise, once round, on both bodies
    assert again.plan == m.plan


def test_a_plan_of_any_shape_is_read_or_refused_in_a_sentence():
    """Fields of every type in every place of a plan: read, or a ShapeMoveError, never a traceback."""
    import copy
    import random

    rng = random.Random(0)
    values = [None, True, 0, -1, 1e9, float("nan"), "x", "", [], {}, [1], {"a": 1}, 3.5, "left hand", ["walk"], ["run", "x"]]
    keys = ["actions", "legs", "arms", "course", "course_way", "turn_degrees", "travel", "in_place", "distance_m",
            "steps", "stop", "stand_still", "count", "pace", "side", "unused"]
    bases = [plan_json(p, 4) for p in ("a person walks forward, then sits down", "a woman jogs while waving her left hand",
                                       "a man jumps twice", "someone kicks with the left leg")]
    refused = 0
    for _ in range(600):
        plan = copy.deepcopy(rng.choice(bases))
        seg, r = rng.choice(plan["segments"]), rng.random()
        if r < 0.6:
            seg["understood"][rng.choice(keys)] = rng.choice(values)
        elif r < 0.75:
            seg[rng.choice(["text", "seconds", "understood"])] = rng.choice(values)
        else:
            plan[rng.choice(["seconds", "segments", "prompt"])] = rng.choice(values)
        try:
            plan_from_json(json.dumps(plan))
        except ShapeMoveError:
            refused += 1
    assert 200 < refused < 600   # many refused, many read


def test_the_length_the_words_ask_is_the_motions(tmp_path, capsys):
    """"for 3 seconds" makes a 3 s motion, said on the understood line; ``--seconds`` wins and says so."""
    out = tmp_path / "m.npz"
    assert main(["generate", "--prompt", "a person waves for 3 seconds", "--candidates", "1", "--out", str(out)]) == 0
    assert "for 3 s" in capsys.readouterr().out and load_motion(out).num_frames == 60
    assert main(["generate", "--prompt", "a person waves for 3 seconds", "--seconds", "2", "--candidates", "1",
                 "--out", str(out)]) == 0
    assert "--seconds 2 won over the 3 s" in capsys.readouterr().out and load_motion(out).num_frames == 40


def test_the_panel_shows_the_words_length_and_zero_gives_it_up():
    from shapemove.core.plan.panel_fields import edited_plan, plan_fields
    from shapemove.core.plan.plan import plan_from_json

    plan = plan_json("a man jogs for 6 seconds, then waves")
    fields = plan_fields(plan)
    assert [f["seconds"] for f in fields] == [6.0, 3.0]
    assert plan_from_json(edited_plan(plan, fields)).lengths(None) == [6.0, 3.0]
    fields[0]["seconds"] = fields[1]["seconds"] = 0.0                 # both the segment's share again
    back = plan_from_json(edited_plan(plan, fields))
    assert back.segments[0].words.seconds is None and back.lengths(8.0) == [4.0, 4.0]
