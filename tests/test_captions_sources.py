"""Captions, shape texts, clip discovery and splits (the parts of the builder that need no model)."""
from pathlib import Path

import pytest

from shapemove.core.data import captions as cap
from shapemove.core.data.shape_text import parse_shape_sentence, shape_adjectives, shape_sentence
from shapemove.core.data.sources import discover
from shapemove.core.data.splits import split_of


def test_bandai_captions_use_content_and_style():
    cid = "dataset-2_wave-left-hand_elderly_001"
    caps = cap.bandai_captions("wave-left-hand", "elderly", cid)
    assert len(caps) == cap.N_CAPTIONS == 6 and len(set(caps)) == 6
    assert caps[0] == "A person waves with the left hand slowly, like an elderly person."  # plainest first
    assert all("wav" in c and "left" in c for c in caps)
    assert all("elderly" in c for c in caps)              # the style in every sentence (adverb or subject)
    assert any(" is waving" in c for c in caps)           # progressive sentence shape
    assert all(c[0].isupper() and c.endswith(".") for c in caps)
    assert caps == cap.bandai_captions("wave-left-hand", "elderly", cid)  # deterministic per clip
    assert caps[1:] != cap.bandai_captions("wave-left-hand", "elderly", "dataset-2_wave-left-hand_elderly_002")[1:]


def test_normal_style_adds_no_manner():
    caps = cap.bandai_captions("run", "normal", "x")
    assert all("normal" not in c for c in caps)
    assert caps[0] == "A person runs forward."


def test_styles_as_adverbs():
    caps = cap.bandai_captions("walk", "happy", "dataset-1_walk_happy_003", n=20)
    assert any(c.startswith(("Happily, ", "Cheerfully, ")) for c in caps)      # adverb first
    assert any(c.endswith(("happily.", "cheerfully.")) for c in caps)          # adverb last
    assert any(c.startswith("A happy person ") for c in caps)                 # style as the subject


def test_gerunds():
    pairs = {"walks": "walking", "runs": "running", "lies": "lying", "dances": "dancing", "hops": "hopping",
             "punches": "punching", "does": "doing", "squats": "squatting", "waves": "waving", "ties": "tying"}
    assert {v: cap.gerund(v) for v in pairs} == pairs
    assert cap.progressive("jumps and turns in the air") == "jumping and turning in the air"
    assert cap.progressive("crawls on hands and knees") == "crawling on hands and knees"


def test_hdm05_class_phrases():
    assert cap.hdm05_phrase("kickLFront1Reps") == "kicks forward with the left leg"
    assert cap.hdm05_phrase("jogLeftCircle4StepsRstart") == "jogs in a circle to the left"
    assert "once" in " ".join(cap.hdm05_captions("squat1Reps", "HDM_bd_squat1Reps_001_120", n=5))
    assert cap.hdm05_phrase("cartwheelLHandStart1Reps") == "performs the action cartwheel l hand start"


def test_cmu_captions_prefer_kit_sentences():
    kit = {"02_01": [{"text": "a person walks forward slowly.", "start": 0, "end": 3}]}
    caps = cap.cmu_captions("02_01", kit, "walk")
    assert caps[0] == "A person walks forward slowly." and len(caps) >= 3
    assert all("walk" in c for c in caps)
    fallback = cap.cmu_captions("01_02", kit, "playground - climb")
    assert fallback and all("climb" in c for c in fallback)
    assert cap.cmu_captions("99_99", kit, None) == []


def test_cmu_multi_action_trials_say_what_they_hold():
    caps = cap.cmu_captions("13_30", None, "jumping jacks, side twists, squats, jog")
    assert caps[0] == "A person does jumping jacks, does side twists, does a squat, then jogs."
    assert any("jumping jacks, side twists, squats, jog" in c for c in caps)
    # alternatives ("run/jog") are one action, not a sequence; styles become adverbs
    assert cap.cmu_captions("02_03", None, "run/jog")[0] == "A person runs."
    assert cap.cmu_captions("105_13", None, "SadWalk")[0] == "A person walks sadly."
    assert cap.cmu_captions("105_01", None, "WalkDigital8")[0] == "A person walks in a figure eight."


def test_deepmimic_captions_from_motion_names():
    assert cap.deepmimic_captions("cartwheel", "deepmimic_cartwheel")[0] == "A person does a cartwheel."
    assert cap.deepmimic_captions("long_walk2_mirror", "x")[0] == "A person walks around."
    assert cap.deepmimic_captions("stealthy_walk0", "x")[0] == "A person sneaks forward."


MEAS = {"height_cm": 182.4, "chest_cm": 101.2, "waist_cm": 99.6, "hip_cm": 104.0,
        "arm_length_cm": 61.0, "leg_length_cm": 86.3}


def test_shape_sentence_round_trip():
    s = shape_sentence(MEAS, gender="male")
    assert s.startswith("A male standing 182 cm tall, with a chest circumference of 101 cm")
    parsed = parse_shape_sentence(s)
    for k, v in MEAS.items():
        assert parsed[k] == pytest.approx(round(v), abs=0.5)


def test_shape_adjectives():
    assert shape_adjectives(MEAS, "male") == "a tall, heavy-set man"  # WHtR 0.546
    slim = dict(MEAS, height_cm=158.0, waist_cm=64.0)                  # WHtR 0.405
    assert shape_adjectives(slim, "female") == "a short, slim woman"
    avg = dict(MEAS, height_cm=172.0, waist_cm=80.0)
    assert shape_adjectives(avg) == "an average-sized person"


def test_splits_hold_out_subjects_and_are_stable():
    assert split_of("HDM_dg_squat1Reps_001_120", "hdm05-dg", "hdm05") == "test"
    assert split_of("HDM_bd_squat1Reps_001_120", "hdm05-bd", "hdm05") == "train"
    ids = [f"dataset-1_walk_happy_{i:03d}" for i in range(2000)]
    splits = [split_of(i, "bandai-dataset-1", "bandai") for i in ids]
    assert 0.07 < splits.count("test") / len(ids) < 0.13
    assert 0.03 < splits.count("val") / len(ids) < 0.07
    assert splits == [split_of(i, "bandai-dataset-1", "bandai") for i in ids]
    # DeepMimic: one clip per action, mirrored copies -> all training data
    assert {split_of(f"deepmimic_{m}", "deepmimic", "deepmimic") for m in ("backflip", "long_walk2", "zombie_walk")} == {"train"}


def test_discover_shared_layout(mocap_root):
    clips = discover(Path(mocap_root))
    by = {}
    for c in clips:
        by.setdefault(c.dataset, []).append(c)
    assert len(by["bandai"]) == 2770 and len(by["hdm05"]) == 232
    # CMU: every trial once, ASF/AMC preferred over its BVH conversion
    trials = [c.id for c in by["cmu"]]
    assert len(trials) == len(set(trials)) and "cmu_02_01" in trials
    assert next(c for c in by["cmu"] if c.id == "cmu_02_01").path.suffix == ".amc"
    assert all(c.captions for c in clips)
    hd = next(c for c in by["hdm05"] if c.id == "HDM_bd_kickLFront1Reps_001_120")
    assert hd.skeleton_path.name == "HDM_bd.asf" and hd.skeleton_path.is_file()
    assert "CC BY-NC" in by["bandai"][0].licence
    # cmu_extra.tar.xz adds 107 CMU trials (no id clashes with cmu.tar.xz), deepmimic.tar.xz 29 clips
    assert len(by["cmu"]) == 185 and "cmu_105_16" in trials and "cmu_13_30" in trials
    assert len(by["deepmimic"]) == 29
    dm = {c.id: c for c in by["deepmimic"]}
    assert dm["deepmimic_cartwheel"].labels["actions"] == ["cartwheel"]
    assert dm["deepmimic_long_walk1_mirror"].labels == {"motion": "long_walk1_mirror", "mirrored": True,
                                                       "actions": ["walk"]}
    assert dm["deepmimic_walk"].licence.startswith("MIT")
    # every clip has actions from the vocabulary except two CMU trials whose description names none
    cmu = {c.id: c for c in by["cmu"]}
    assert cmu["cmu_13_30"].labels["actions"][:4] == ["jumping jacks", "side twist", "squat", "jog"]
    assert cmu["cmu_105_16"].labels["actions"] == ["limp", "walk"]  # main action first
    assert by["bandai"][0].labels["actions"] and hd.labels["actions"] == ["kick"]
    assert sorted(c.id for c in clips if not c.labels["actions"]) == ["cmu_105_37", "cmu_105_38"]


def test_discover_generic_folder_with_captions(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "jump.bvh").write_text("HIERARCHY\n")
    (tmp_path / "a" / "jump.txt").write_text("a person jumps.\n\nsomeone hops up.\n")
    clips = discover(tmp_path)
    assert [c.id for c in clips] == ["a__jump"]
    assert clips[0].captions == ["a person jumps.", "someone hops up."]
    assert clips[0].dataset == "user"
