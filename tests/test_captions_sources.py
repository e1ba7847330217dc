"""Captions, shape texts, clip discovery and splits (the parts of the builder that need no model)."""
from pathlib import Path

import pytest

from shapemove.core.data import captions as cap
from shapemove.core.data.shape_text import parse_shape_sentence, shape_adjectives, shape_sentence
from shapemove.core.data.sources import discover
from shapemove.core.data.splits import split_of


def test_bandai_captions_use_content_and_style():
    caps = cap.bandai_captions("wave-left-hand", "elderly", "dataset-2_wave-left-hand_elderly_001")
    assert len(caps) == 3 and len(set(caps)) == 3
    assert all("waves with the left hand" in c for c in caps)
    assert any("elderly" in c for c in caps)
    assert all(c[0].isupper() and c.endswith(".") for c in caps)
    # deterministic per clip
    assert caps == cap.bandai_captions("wave-left-hand", "elderly", "dataset-2_wave-left-hand_elderly_001")


def test_normal_style_adds_no_manner():
    caps = cap.bandai_captions("run", "normal", "x")
    assert all("normal" not in c for c in caps)


def test_hdm05_class_phrases():
    assert cap.hdm05_phrase("kickLFront1Reps") == "kicks forward with the left leg"
    assert cap.hdm05_phrase("jogLeftCircle4StepsRstart") == "jogs in a circle to the left"
    assert "once" in " ".join(cap.hdm05_captions("squat1Reps", "HDM_bd_squat1Reps_001_120", n=5))
    assert cap.hdm05_phrase("cartwheelLHandStart1Reps") == "performs the action cartwheel l hand start"


def test_cmu_captions_prefer_kit_sentences():
    kit = {"02_01": [{"text": "a person walks forward slowly.", "start": 0, "end": 3}]}
    assert cap.cmu_captions("02_01", kit, "walk") == ["A person walks forward slowly."]
    fallback = cap.cmu_captions("01_02", kit, "playground - climb")
    assert fallback and all("climb" in c for c in fallback)
    assert cap.cmu_captions("99_99", kit, None) == []


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


def test_discover_generic_folder_with_captions(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "jump.bvh").write_text("HIERARCHY\n")
    (tmp_path / "a" / "jump.txt").write_text("a person jumps.\n\nsomeone hops up.\n")
    clips = discover(tmp_path)
    assert [c.id for c in clips] == ["a__jump"]
    assert clips[0].captions == ["a person jumps.", "someone hops up."]
    assert clips[0].dataset == "user"
