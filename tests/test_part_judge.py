"""The part judge (core/eval/part_judge.py) on real captured clips of the tiny dataset: the side that
moves, the gait of the legs, the path, the arms, and its refusals."""
import json

import numpy as np
import pytest

from shapemove.core.data.mirror import mirror_joints
from shapemove.core.errors import ShapeMoveError
from shapemove.core.eval.part_judge import (CIRCLE, NO_GESTURE, STRAIGHT, PartJudge, actions_of, arms_label,
                                            dominant_frequency, joints_of, legs_descriptor, legs_label, legs_right,
                                            load_joints, path_of, side_activity, side_of, straight_joints)
from shapemove.core.eval.part_judge_accuracy import leave_one_out, named_side, real_accuracy
from shapemove.core.motion.root_speed import steady_span

WAVE_LEFT = "dataset-2_wave-left-hand_elderly_001"
KICK_LEFT = "HDM_bd_kickLFront1Reps_001_120"
WALKS = ["dataset-1_walk_feminine_001", "dataset-2_walk_masculine_003"]
RUNS = ["dataset-1_run_happy_001", "cmu_09_01"]  # the elderly run (no flight phase, slower than a brisk walk) reads as a walk


def metas(data):
    return [json.loads(ln) for ln in (data / "meta.jsonl").read_text().splitlines() if ln.strip()]


@pytest.fixture(scope="module")
def judge(tiny_dataset):
    real = [m for m in metas(tiny_dataset) if not m.get("augmented_from") and not m["id"].endswith("_aug")]
    return PartJudge.from_metas(tiny_dataset, real, progress=False)


def test_side_of_a_left_hand_wave_and_its_mirror(tiny_dataset):
    j = load_joints(tiny_dataset, WAVE_LEFT)
    left, right = side_activity(j, "hand")
    assert left > 2 * right                                    # the waving hand travels far more
    assert side_of(j, "hand") == "left"
    m = mirror_joints(j)
    assert side_activity(m, "hand") == pytest.approx((right, left), rel=1e-6)   # the mirror swaps them exactly
    assert side_of(m, "hand") == "right"


def test_side_of_a_left_kick_and_its_mirror(tiny_dataset):
    j = load_joints(tiny_dataset, KICK_LEFT)
    left, right = side_activity(j, "foot")
    assert left > 1.5 * right
    assert side_of(j, "foot") == "left" and side_of(mirror_joints(j), "foot") == "right"


def test_legs_tell_walks_from_runs_without_their_own_clip(judge, tiny_dataset):
    """Without its own clip the tiny set's runs are one happy run and an elderly run that reads as a
    walk: CMU's 1.15 s run is read as a gait with flight, a run or the jog (scores within 4 %)."""
    for cid, want in [(c, "walk") for c in WALKS] + [(RUNS[0], "run")]:
        j = load_joints(tiny_dataset, cid)
        assert judge.legs.classify(j, exclude_source=cid) == want, cid
        assert judge.legs.classify(mirror_joints(j), exclude_source=cid) == want, cid   # side-invariant
    assert judge.legs.classify(load_joints(tiny_dataset, RUNS[1]), exclude_source=RUNS[1]) in ("run", "jog")


def test_arms_of_locomotion_are_no_gesture_and_a_wave_is_not(judge, tiny_dataset):
    for cid in WALKS + RUNS:
        assert judge.arms.classify(load_joints(tiny_dataset, cid), exclude_source=cid) == NO_GESTURE, cid
    wave = load_joints(tiny_dataset, WAVE_LEFT)
    assert judge.judge_joints(mirror_joints(wave[10:]))["arms"] == "wave"     # a part of it, mirrored
    assert judge.judge_joints(wave)["legs"] == "stand"


def test_path_circles_for_a_jog_in_a_circle_only(tiny_dataset):
    assert path_of(load_joints(tiny_dataset, "HDM_bk_jogLeftCircle4StepsRstart_003_120")) == CIRCLE
    for cid in WALKS + RUNS:
        assert path_of(load_joints(tiny_dataset, cid)) == STRAIGHT, cid
    assert legs_right(CIRCLE, {"legs": "jog", "path": CIRCLE}) and not legs_right(CIRCLE, {"legs": "jog", "path": STRAIGHT})
    assert not legs_right(CIRCLE, {"legs": "stand", "path": CIRCLE}) and legs_right("jog", {"legs": "jog", "path": CIRCLE})


def test_legs_read_the_gait_whatever_the_path(judge, tiny_dataset):
    """A jog circling left and the same steps straight: the path tells them apart, the legs do not
    (every descriptor group within 0.02 of the circle's; a walk's groups differ by 0.05 to 0.7), and
    the judge reads the straight copy as it reads the take (a gait read by its turning did not)."""
    jog = load_joints(tiny_dataset, "HDM_bk_jogLeftCircle4StepsRstart_003_120")
    straight = straight_joints(jog)
    assert path_of(jog) == CIRCLE and path_of(straight) == STRAIGHT
    a, b = legs_descriptor(jog), legs_descriptor(straight)
    assert set(a) == set(b) and all(np.abs(a[g] - b[g]).max() < 0.02 for g in a)
    walk = legs_descriptor(load_joints(tiny_dataset, WALKS[0]))
    assert max(np.abs(a[g] - walk[g]).max() for g in a) > 0.3
    assert judge.legs.classify(straight) == judge.legs.classify(jog) == "jog"


def test_labels_and_named_sides():
    assert legs_label(["jog", "walk in a circle"]) == "jog" and legs_label(["walk in a circle"]) == "walk"
    assert legs_label(["wave"]) == "stand" and arms_label(["wave goodbye"]) == "wave"
    assert arms_label(["walk"]) == NO_GESTURE and arms_label(["walk", "wave"]) is None and legs_label(["kick"]) is None
    assert named_side({"dataset": "bandai", "labels": {"content": "raise-up-right-hand"}}) == ("right", "hand")
    assert named_side({"dataset": "bandai", "labels": {"content": "wave-both-hands"}}) is None
    assert named_side({"dataset": "hdm05", "labels": {"class": "kickLFront1Reps"}}) == ("left", "foot")
    assert named_side({"dataset": "hdm05", "labels": {"class": "grabHighR"}}) == ("right", "hand")


def test_real_accuracy_counts_each_named_side_and_its_mirror(judge, tiny_dataset):
    real = [m for m in metas(tiny_dataset) if not m["id"].endswith("_aug")]
    res = real_accuracy(judge, tiny_dataset, metas=real, progress=False)
    named = [m for m in real if named_side(m)]
    assert {m["id"] for m in named} >= {WAVE_LEFT, KICK_LEFT}
    assert res["side"]["n"] == 2 * len(named) and res["side"]["accuracy"] == 1.0
    assert res["side"]["confusion"] == {"left": {"left": len(named)}, "right": {"right": len(named)}}
    loo = leave_one_out(judge)
    # each tiny-set run judged among the others: the happy run reads as one, the elderly run (no
    # flight) as a walk, CMU's short run as a run or the jog (test_legs_tell_walks_from_runs...)
    run = loo["legs"]["per_class"]["run"]
    assert run["n"] == 3 and run["accuracy"] >= 1 / 3 and set(loo["legs"]["confusion"]["run"]) <= {"run", "walk", "jog"}
    assert loo["legs"]["per_class"]["walk"]["n"] >= 2


def test_bad_input_is_refused(tiny_dataset):
    with pytest.raises(ShapeMoveError, match="features must be"):
        joints_of(np.zeros((20, 100)))
    with pytest.raises(ShapeMoveError, match="at least 10 frames"):
        side_of(np.zeros((3, 22, 3)), "hand")
    with pytest.raises(ShapeMoveError, match="NaN"):
        joints_of(np.full((20, 263), np.nan))
    with pytest.raises(ShapeMoveError, match="part must be one of"):
        side_of(load_joints(tiny_dataset, WAVE_LEFT), "elbow")
    with pytest.raises(ShapeMoveError, match="not a built dataset"):
        PartJudge.from_data(tiny_dataset / "meta")


def test_leave_one_out_reads_each_reference_without_its_own_take():
    """A class of one captured take is never read right once that take is left out; a clip and
    its source's own mirrored take (``m``, ``m_mirror``) are one take."""
    from shapemove.core.eval.part_judge import PartKNN, best

    # each reference clip is followed by its mirror image (the judge's layout): same source
    pos = [0.0, 0.1, 0.05, 0.15, 1.0, 1.1, 2.0, 2.0, 2.05, 2.05]
    labels = ["a"] * 4 + ["b"] * 2 + ["c"] * 4
    sources = ["a1", "a1", "a2", "a2", "b1", "b1", "m", "m", "m_mirror", "m_mirror"]
    knn = PartKNN([{"g": np.array([p])} for p in pos], labels, sources, describe=None, k=1)

    class Judge:
        legs = arms = knn

    loo = leave_one_out(Judge())["legs"]["per_class"]
    assert loo["a"] == {"n": 2, "accuracy": 1.0, "takes": 2}    # a1 finds a2, and back
    assert loo["b"] == {"n": 1, "accuracy": 0.0, "takes": 1}    # b1 alone: its nearest other is an "a"
    assert loo["c"] == {"n": 2, "accuracy": 0.0, "takes": 1}    # m without m_mirror (one take): a "b"
    # judged with every reference (a motion that is no copy), each point reads as its own class
    assert [best(knn.scores_of(x)) for x in knn.X] == labels


def test_reachable_parts_averages_the_expected_classes_of_the_prompts():
    from shapemove.core.eval.parts_eval import reachable_parts

    reach = {"legs": {"per_class": {"walk": {"accuracy": 0.9}, "march": {"accuracy": 0.0}}},
             "arms": {"per_class": {"wave": {"accuracy": 1.0}, "punch": {"accuracy": 0.5}}}}
    items = [{"legs": "walk in a circle", "arms": "wave goodbye"}, {"legs": "march", "arms": "punch"},
             {"legs": "walk", "arms": "beckon"}]   # beckon: no reference at all, 0
    out = reachable_parts(reach, items)["two_things"]
    assert out["legs"] == pytest.approx((0.9 + 0.0 + 0.9) / 3)
    assert out["arms"] == pytest.approx((1.0 + 0.5 + 0.0) / 3)
    assert out["both"] == pytest.approx((0.9 * 1.0 + 0.0 + 0.0) / 3)


def test_the_bar_leaves_out_single_take_classes_and_is_0_9x_the_real_reach():
    """Hand-derived: the march + wave prompt is left out (march has one take); over the two walk
    prompts legs are right 2 of 2, arms 1 of 2, both 1 of 2; real copies are credited with legs
    0.9, arms 1.0 x 0.5 = ... per prompt (wave 1.0, punch 0.5): arms 0.75, both (0.9 + 0.45) / 2."""
    from shapemove.core.eval.parts_eval import barred_parts

    reach = {"legs": {"per_class": {"walk": {"accuracy": 0.9, "takes": 150}, "march": {"accuracy": 0.0, "takes": 1}}},
             "arms": {"per_class": {"wave": {"accuracy": 1.0, "takes": 150}, "punch": {"accuracy": 0.5, "takes": 4}}}}
    rows = [{"pair": "walk + wave", "legs": "walk", "arms": "wave goodbye", "legs_right": True, "arms_right": True,
             "both_right": True},
            {"pair": "walk + punch", "legs": "walk", "arms": "punch", "legs_right": True, "arms_right": False,
             "both_right": False},
            {"pair": "march + wave", "legs": "march", "arms": "wave", "legs_right": True, "arms_right": True,
             "both_right": True}]
    b = barred_parts(rows, reach)
    assert b["prompts"] == 2 and b["left_out"] == ["march + wave"]
    assert (b["both"], b["legs"], b["arms"]) == (0.5, 1.0, 0.5)
    assert b["reachable"] == pytest.approx({"legs": 0.9, "arms": 0.75, "both": (0.9 + 0.45) / 2})
    assert b["bar"] == pytest.approx({"legs": 0.81, "arms": 0.675, "both": 0.9 * 0.675})
    assert b["met"] is False                         # arms 0.5 < 0.675
    rows[1]["arms_right"] = rows[1]["both_right"] = True
    assert barred_parts(rows, reach)["met"] is True


def test_format_results_names_what_copies_could_score():
    from shapemove.core.eval.parts_eval import TARGETS, format_results, reachable_parts

    loo = {"legs": {"per_class": {"walk": {"accuracy": 0.9, "takes": 150}, "march": {"accuracy": 0.0, "takes": 1}}},
           "arms": {"per_class": {"wave": {"accuracy": 1.0, "takes": 150}}}}
    res = {"sides": {"named_side_moves_most": 1.0, "prompts": 1, "per_part": {"hand": {"right": 1.0, "n": 1}}},
           "two_things": {"both": 0.0, "legs": 0.5, "arms": 1.0, "prompts": 2, "per_pair": {}},
           "targets": TARGETS, "judge_real": None,
           "reachable": reachable_parts(loo, [{"legs": "walk", "arms": "wave"}, {"legs": "march", "arms": "wave"}]),
           "settings": {"seed": 0, "seconds": 4.0, "candidates": 8, "retrieval": "on"},
           "rows": {"sides": [], "two_things": []}}
    text = format_results(res)
    assert "could score: legs 45.0%, arms 100.0%, both 45.0%" in text
    assert "march 0.0% (1 take)" in text and "walk" not in text.split("this way:")[1]


def pelvis_path(speeds):
    """(T, 22, 3) joints whose pelvis goes forward at ``speeds`` (m/s, one per frame step), the rest at 0."""
    z = np.concatenate([[0.0], np.cumsum(np.asarray(speeds, float) / 20)])
    j = np.zeros((len(z), 22, 3))
    j[:, 0, 2] = z
    return j


def test_steady_span_is_the_stretch_at_cruising_speed():
    """Speeds 0.05 -> 1.95 m/s over 20 steps, 40 at 2, 2.05 -> 0.15 over 20: cruising 2 m/s, >= 1.6
    from step 16 (0.1 t + 0.05) to step 64 (2.05 - 0.1 (t - 60)); the ramps are linear, the smoothing
    keeps them so: frames 16 to 66 (a step joins two frames)."""
    ramp = np.arange(20) / 20 * 2.0 + 0.05
    assert steady_span(pelvis_path(np.concatenate([ramp, np.full(40, 2.0), ramp[::-1] + 0.1]))) == (16, 66)
    assert steady_span(pelvis_path(np.full(60, 1.5))) is None                           # steady throughout
    assert steady_span(pelvis_path(np.concatenate([ramp, np.full(10, 2.0), ramp[::-1]]))) is None   # under 1 s


def test_the_steady_stretch_of_a_jog_reads_as_a_jog(judge, tiny_dataset):
    """HDM05's jogs are 4 steps from standing: their steady stretch, as a looped jog plays, is
    matched by the references' own steady stretches (12 of 14 real ones read as walks or runs
    against the whole takes alone); the stretches are references, not clips."""
    jog = load_joints(tiny_dataset, "HDM_bk_jogLeftCircle4StepsRstart_003_120")
    a, b = steady_span(jog)
    assert 20 <= b - a <= 0.8 * len(jog)
    assert judge.legs.classify(straight_joints(jog[a:b])) == "jog"
    assert judge.legs.stretches.sum() > 0 and not judge.arms.stretches.any()
    whole = ~judge.legs.stretches
    assert judge.info["legs_references"]["jog"] == int((whole & (judge.legs.labels == "jog")).sum() // 2) == 1


def test_the_legs_pose_leaves_out_the_skeleton_and_the_lean(tiny_dataset):
    """The legs, hips to feet, 4 cm to one side of the pelvis (a lean into a turn) leave the legs'
    pose and spread as they were; hips 6 cm wider (the skeleton) move them only as much as the leg's length, hip to ankle,
    changes (under 0.5 %: the hips are not in them); the knees 4 cm further apart do."""
    jog = straight_joints(load_joints(tiny_dataset, "HDM_bk_jogLeftCircle4StepsRstart_003_120"))   # faces +Z: x is across
    base = legs_descriptor(jog)
    wide, lean, knees = jog.copy(), jog.copy(), jog.copy()
    wide[:, 1, 0] += 0.03
    wide[:, 2, 0] -= 0.03
    lean[:, [1, 2, 4, 5, 7, 8, 10, 11], 0] += 0.04
    knees[:, 4, 0] += 0.02
    knees[:, 5, 0] -= 0.02
    d = legs_descriptor(lean)   # (the body sways about +Z: across is x to within a few degrees)
    assert np.abs(d["pose"] - base["pose"]).max() < 0.002 and np.abs(d["spread"] - base["spread"]).max() < 0.002   # 4 cm: 0.045
    d = legs_descriptor(wide)
    assert np.abs(d["pose"] - base["pose"]).max() < 0.005 and np.abs(d["spread"] - base["spread"]).max() < 0.005
    assert np.abs(legs_descriptor(knees)["pose"] - base["pose"]).max() > 0.02


def test_the_stride_frequency_is_resolved_finely():
    """A 1.3 Hz swing over 3 s: the 256-sample spectrum finds it within its 0.08 Hz spacing, the
    64-sample one at its nearest 0.31 Hz step (1.25)."""
    x = np.sin(2 * np.pi * 1.3 * np.arange(60) / 20)
    assert abs(dominant_frequency(x, 256)[0] - 1.3) < 0.04
    assert dominant_frequency(x, 64)[0] == pytest.approx(1.25)


def test_steady_accuracy_reads_each_locomotion_clip_s_steady_stretch(judge, tiny_dataset):
    from shapemove.core.eval.part_judge_accuracy import steady_accuracy

    splits = tuple(sorted({m["split"] for m in metas(tiny_dataset) if m.get("split")}))
    res = steady_accuracy(judge, tiny_dataset, splits, progress=False)
    want = []
    for m in metas(tiny_dataset):
        copy = m.get("augmented_from") or m["id"].endswith("_aug")
        gait = legs_label(actions_of(m)) if m.get("split") and not copy else None
        j = load_joints(tiny_dataset, m["id"]) if gait not in (None, "stand") else None
        if j is not None and steady_span(j) is not None:
            want.append(gait)
    assert res["n"] == len(want) >= 1 and sorted(res["per_class"]) == sorted(set(want))
    assert "jog" in want   # HDM05's 4 steps from standing has one; the tiny set's only jog, without its take, has no jog to match
