"""tools/codec_action_check.py: which captured clips it encodes (the judging is eval paraphrase's)."""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

TOOL = Path(__file__).resolve().parents[1] / "tools" / "codec_action_check.py"


def _tool():
    spec = importlib.util.spec_from_file_location("codec_action_check", TOOL)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_only_captured_clips_of_each_main_action_are_drawn(tmp_path):
    metas = {"kick_1": {"labels": {"actions": ["kick", "walk"]}},
             "kick_2": {"labels": {"actions": ["kick"]}},
             "kick_3": {"labels": {"actions": ["kick"]}},
             "kick_1_mirror": {"labels": {"actions": ["kick"]}, "mirror_of": "kick_1"},
             "kick_2_aug": {"labels": {"actions": ["kick"]}, "augmented_from": "kick_2"},
             "both": {"labels": {"actions": ["kick"]}, "composed_from": ["kick_1", "walk_1"]},
             "walk_1": {"labels": {"actions": ["walk", "kick"]}},
             "test_kick": {"labels": {"actions": ["kick"]}}}
    (tmp_path / "meta").mkdir()
    for cid, m in metas.items():
        (tmp_path / "meta" / f"{cid}.json").write_text(json.dumps({"id": cid, **m}))
    (tmp_path / "train.txt").write_text("\n".join(c for c in metas if c != "test_kick") + "\n")
    (tmp_path / "test.txt").write_text("test_kick\n")
    captured_clips = _tool().captured_clips
    drawn = captured_clips(tmp_path, "train", ["kick", "walk", "punch"], per_action=5)
    assert sorted(drawn) == [("kick", "kick_1"), ("kick", "kick_2"), ("kick", "kick_3"), ("walk", "walk_1")]
    two = captured_clips(tmp_path, "train", ["kick"], per_action=2, seed=3)
    assert len(two) == 2 and {c for _, c in two} <= {"kick_1", "kick_2", "kick_3"}
    assert two == captured_clips(tmp_path, "train", ["kick"], per_action=2, seed=3)   # seeded
    assert captured_clips(tmp_path, "test", ["kick"], per_action=5) == [("kick", "test_kick")]
