"""eval codec-actions: which captured clips it encodes (the judging is eval paraphrase's) and the
extremity figures it sets capture against decoding."""
from __future__ import annotations

import json

import numpy as np
import torch

from shapemove.core.eval.codec_actions import captured_clips, extremities


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
    drawn = captured_clips(tmp_path, "train", ["kick", "walk", "punch"], per_action=5)
    assert sorted(drawn) == [("kick", "kick_1"), ("kick", "kick_2"), ("kick", "kick_3"), ("walk", "walk_1")]
    two = captured_clips(tmp_path, "train", ["kick"], per_action=2, seed=3)
    assert len(two) == 2 and {c for _, c in two} <= {"kick_1", "kick_2", "kick_3"}
    assert two == captured_clips(tmp_path, "train", ["kick"], per_action=2, seed=3)   # seeded
    assert captured_clips(tmp_path, "test", ["kick"], per_action=5) == [("kick", "test_kick")]
    assert captured_clips(tmp_path, "val", ["kick"], per_action=5) == []              # no such split


def test_extremities_read_a_raised_foot_and_a_reaching_hand():
    """A standing body (the canonical rest joints) whose left foot is lifted 0.6 m and whose right
    hand is moved 0.5 m forward in the middle frames: the figures read those, within a centimetre."""
    from shapemove.core.body.load import load_body_model
    from shapemove.core.motion.features import features_from_joints

    rest = load_body_model(None).rest_joints(torch.zeros(1, 10))[0, :22].numpy()
    rest = rest - [0, rest[:, 1].min(), 0]
    still = extremities(features_from_joints(np.repeat(rest[None], 40, axis=0), keep_height=True))
    joints = np.repeat(rest[None], 40, axis=0)
    joints[15:25, [7, 10], 1] += 0.6          # left ankle and foot up
    joints[15:25, 21, 2] += 0.5               # right wrist forward
    moved = extremities(features_from_joints(joints, keep_height=True))
    assert abs(moved["foot_height"] - still["foot_height"] - 0.6) < 0.01
    assert abs(moved["hand_reach"] - np.hypot(rest[21, 0] - rest[0, 0], rest[21, 2] - rest[0, 2] + 0.5)) < 0.01
    assert abs(moved["hand_height"] - still["hand_height"]) < 0.01
