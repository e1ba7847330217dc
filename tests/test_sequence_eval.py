"""eval sequences (core/eval/sequence_eval.py): a one-prompt sequence's expected actions, the plan's
split, each segment of a motion judged where the motion records it, the order, and the command."""
import json

import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.eval.sequence_eval import (ACTION, ARMS, LEGS, SIGNATURE, expected_actions, in_order, judge_of,
                                               judge_prompt, load_sequences, motion_order, shows, split_right, tally)
from tiny_models import tiny_bundle  # noqa: F401  (session fixture)

WALK, WAVE, KICK = "dataset-1_walk_feminine_001", "dataset-2_wave-left-hand_elderly_001", "dataset-1_kick_normal_001"


def test_expected_actions_are_the_vocabulary_at_each_word():
    # the words in the order things happen, found where they stand ('kick' comes first in the text)
    assert expected_actions("before kicking the ball, he jogs forward", ["jog", "kick"]) == ["jog", "kick ball"]
    assert expected_actions("a man walks on, turns, then walks back", ["walk", "walk"]) == ["walk", "walk"]
    assert expected_actions("after waving goodbye she strolls off", ["wav", "stroll"]) == ["wave goodbye", "walk"]
    assert expected_actions("he gets up, then bends over", ["get", "bend"]) == ["get up", "bend over"]
    # no action of the vocabulary covers the word, or the word is not there: not guessed
    assert expected_actions("a man salutes, then nods", ["salute", "nod"]) == [None, None]
    assert expected_actions("a man walks", ["walk", "walk"]) == ["walk", None]


def test_split_right_needs_each_word_in_its_segment_in_order():
    assert split_right(["a man waves", "a man jogs"], ["wave", "jog"])
    assert not split_right(["a man jogs", "a man waves"], ["wave", "jog"])
    assert not split_right(["a man waves and then jogs"], ["wave", "jog"])


def test_shipped_set_and_bad_files(tmp_path):
    items = load_sequences()
    assert len(items) >= 40 and all(2 <= len(it["words"]) <= 3 for it in items if it["words"] != ["stop"])
    (tmp_path / "a.json").write_text('{"prompts": [["a man walks, then sits", "walk"]]}')
    with pytest.raises(ShapeMoveError, match="prompt 0 must be"):
        load_sequences(tmp_path / "a.json")
    (tmp_path / "b.json").write_text('{"prompts": []}')
    with pytest.raises(ShapeMoveError, match="no prompts"):
        load_sequences(tmp_path / "b.json")


def test_order_needs_more_of_the_actions_in_place_than_swapped():
    kinds = [LEGS, ARMS]
    walk, wave = {"legs": "walk", "path": "straight", "arms": "none", "action": "walk"}, \
        {"legs": "stand", "path": "straight", "arms": "wave", "action": "wave"}
    assert motion_order(["walk", "wave"], kinds, [walk, wave]) == [[0, 1, 2, 0]]
    assert in_order(motion_order(["walk", "wave"], kinds, [walk, wave])) is True
    assert in_order(motion_order(["walk", "wave"], kinds, [wave, walk])) is False
    both = motion_order(["walk", "wave"], kinds, [walk, walk])   # walking throughout is no order, nor reversed
    assert both == [[0, 1, 1, 1]] and in_order(both) is False and in_order(both, strict=False) is True
    assert in_order(motion_order(["walk", "walk"], [LEGS, LEGS], [walk, walk])) is None   # nothing to order
    assert in_order(motion_order(["walk", None], [LEGS, None], [walk, wave])) is None
    # the first and the last swapped around a middle that stays: every pair counts, not only neighbours
    three = motion_order(["wave", "jump", "walk"], [ARMS, ACTION, LEGS],
                         [walk, {"legs": "stand", "path": "straight", "arms": "none", "action": "jump"}, wave])
    assert [p[:2] for p in three] == [[0, 1], [0, 2], [1, 2]] and in_order(three) is False


def test_a_specific_form_counts_only_when_lenient():
    jump_forward = {"legs": "run", "path": "straight", "arms": "none", "action": "jump forward"}
    assert shows("jump", ACTION, jump_forward) is False and shows("jump", ACTION, jump_forward, lenient=True)
    assert not shows("jump forward", ACTION, {**jump_forward, "action": "jump"}, lenient=True)   # not the other way
    assert shows("walk", LEGS, {**jump_forward, "legs": "sneak"}, lenient=True)
    assert shows("walk", LEGS, jump_forward) is False and shows("wave", None, jump_forward) is None


@pytest.fixture(scope="module")
def judges(tiny_dataset):
    from shapemove.core.data.actions import ACTIONS
    from shapemove.core.eval.action_classifier import ActionClassifier
    from shapemove.core.data.built_meta import is_real
    from shapemove.core.eval.part_judge import PartJudge

    metas = [json.loads(ln) for ln in (tiny_dataset / "meta.jsonl").read_text().splitlines() if ln.strip()]
    judge = PartJudge.from_metas(tiny_dataset, [m for m in metas if is_real(m)], progress=False)
    return judge, ActionClassifier.from_features(tiny_dataset, list(ACTIONS), progress=False)


def test_a_hand_made_motion_is_judged_segment_by_segment(judges, tiny_dataset):
    """Three real clips one after another (a walk, a wave, a kick) with the bounds at their joins:
    each piece is its own clip, so each is judged right where it is and wrong anywhere else."""
    from shapemove.core.eval.action_classifier import load_features

    judge, clf = judges
    clips = [load_features(tiny_dataset, c) for c in (WALK, WAVE, KICK)]
    ends = np.cumsum([len(c) for c in clips])
    bounds = np.stack([np.r_[0, ends[:-1]], ends], 1)
    feats = np.concatenate(clips)
    item = {"text": "a woman walks, then waves, then kicks", "words": ["walk", "wave", "kick"]}
    plan = ["a woman walks", "a woman waves", "a woman kicks"]
    row = judge_prompt(item, plan, feats, bounds, judge, clf)
    assert row["actions"] == ["walk", "wave", "kick"] and row["judges"] == [LEGS, SIGNATURE, SIGNATURE]
    assert row["right"] == [True, True, True] and row["split_right"] and row["order_right"] is True
    assert row["readings"][2]["signatures"]["kick"] and not row["readings"][0]["signatures"]["kick"]
    assert row["right_vote"] == [True, True, True] and row["order_right_vote"] is True   # the wave by the arms
    assert [judge_of(a, judge, clf, signatures=False) for a in row["actions"]] == [LEGS, ARMS, ACTION]
    assert [r["frames"] for r in row["readings"]] == [len(c) for c in clips]
    # the same motion asked in the other order: the ends wrong and the order swapped
    back = {"text": "a woman kicks, then waves, then walks", "words": ["kick", "wave", "walk"]}
    row2 = judge_prompt(back, plan[::-1], feats, bounds, judge, clf)
    # (Bandai's kick steps into it: the legs may read its piece as the walk asked there; the kick asked
    # of the walk's piece is wrong by the signature, and the order is swapped either way)
    assert row2["right"][:2] == [False, True] and row2["order_right"] is False
    # judged whole (no bounds recorded: the plan made one motion): no segment to judge, wrong
    row3 = judge_prompt(item, ["a woman walks, then waves, then kicks"], feats, None, judge, clf)
    assert row3["right"] == [False, False, False] and not row3["split_right"] and row3["order_right"] is False
    res = tally([row, row2, row3])
    assert (res["segments"]["right"], res["segments"]["judged"]) == (4 + row2["right"][2], 9)
    assert res["segments"]["per_action"]["wave"] == {"n": 3, "right": 2, "lenient": 2, "accuracy": pytest.approx(2 / 3)}
    assert (res["order"]["right"], res["order"]["judged"]) == (1, 3)
    assert (res["all_right"]["right"], res["all_right"]["prompts"]) == (1, 3)
    assert (res["split"]["right"], res["split"]["prompts"]) == (2, 3)
    assert (res["segments_vote"]["right"], res["segments_vote"]["judged"]) == (4 + row2["right_vote"][2], 9)
    assert (res["order_vote"]["right"], res["order_vote"]["judged"]) == (1, 3)


def test_eval_sequences_command_on_a_tiny_model(tiny_bundle, tmp_path, capsys):  # noqa: F811
    from shapemove.cli import main
    from shapemove.core.plan.plan import read_plan

    model, data = tiny_bundle
    prompts = {"prompts": [["a man jogs forward, then waves", ["jog", "wave"]],
                           ["after kicking, she walks on, then salutes", ["kick", "walk", "salute"]]]}
    (tmp_path / "p.json").write_text(json.dumps(prompts))
    assert main(["eval", "sequences", "--model", str(model), "--data", str(data), "--prompts", str(tmp_path / "p.json"),
                 "--seconds", "3", "--candidates", "2", "--json", str(tmp_path / "r.json"), "--quiet"]) == 0
    out = capsys.readouterr().out
    res = json.loads((tmp_path / "r.json").read_text())
    rows = res["rows"]
    assert [r["text"] for r in rows] == [p[0] for p in prompts["prompts"]] and [r["seed"] for r in rows] == [0, 1]
    for r, (text, words) in zip(rows, prompts["prompts"]):
        plan = [s.text for s in read_plan(text).segments]
        assert r["plan"] == plan and r["made_as"] == plan and len(r["segment_bounds"]) == len(words)
        b = np.asarray(r["segment_bounds"])   # cut where the motion records its segments: the whole of it, in turn
        assert b[0, 0] == 0 and (b[1:, 0] == b[:-1, 1]).all() and b[-1, 1] == round(r["seconds"] * 20)
        assert [x["frames"] for x in r["readings"]] == [min(e, b[-1, 1] - 1) - s for s, e in b]   # (T-1) features
    assert rows[1]["actions"] == ["kick", "walk", None] and rows[1]["right"][2] is None
    judged = [ok for r in rows for ok in r["right"] if ok is not None]
    assert res["segments"]["judged"] == len(judged) and res["segments"]["right"] == sum(judged)
    assert res["segments"]["unjudged_by_action"] == {"'salute' (no action)": 1}
    assert res["split"]["right"] == 2 and "Held-out one-prompt sequences (p.json, 2 prompts)" in out
    told = {a for r in rows for a, ok in zip(r["actions"], r["right"]) if ok is not None}
    reach = res["reachable"]
    assert set(reach["per_action"]) == told and all(0 <= v <= 1 for v in reach["per_action"].values())
    assert reach["segments"] == pytest.approx(np.mean([reach["per_action"][a] for r in rows
                                                       for a, ok in zip(r["actions"], r["right"]) if ok is not None]))
    assert main(["eval", "sequences", "--model", str(model), "--data", str(data), "--prompts", str(tmp_path / "p.json"),
                 "--max-prompts", "1", "--seconds", "3", "--candidates", "2", "--quiet"]) == 0
    assert "(p.json, 1 prompts)" in capsys.readouterr().out
