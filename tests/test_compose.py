"""Compositions "A, then B" of built clips (core/data/compose.py)."""
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from shapemove.core.data import compose as cp
from shapemove.core.data.actions import known_actions
from shapemove.core.errors import ShapeMoveError
from shapemove.core.geometry.rotations import yaw_matrix


def straight_part(cid, heading, frames=30, speed=0.05, bend=0.0):
    """A synthetic part walking along ``heading`` (radians about +Y from +Z), body facing it."""
    R = np.broadcast_to(np.eye(3), (frames, 24, 3, 3)).copy()
    R[:, 0] = yaw_matrix(heading)
    R[:, 4] = yaw_matrix(bend) if bend else np.eye(3)
    d = yaw_matrix(heading) @ np.array([0.0, 0.0, 1.0])
    root = np.array([0.0, 0.9, 0.0]) + np.arange(frames)[:, None] * speed * d
    return cp.Part(cid, {}, R, root, np.zeros(10, np.float32), np.zeros((frames, 4), np.uint8), "walks")


def test_join_turns_and_moves_b_to_continue_from_a():
    a = straight_part("a", 0.0)                      # walks +Z
    b = straight_part("b", np.pi / 2)                # walks +X, from the origin
    b.root = b.root + [5.0, 0.0, -3.0]               # somewhere else entirely
    rot, root, contacts = cp.join(a, b, scale_b=1.0, blend=10)
    assert rot.shape == (30 + 30 - 10, 24, 3, 3) and root.shape == (50, 3) and contacts.shape == (50, 4)
    # B is turned to face +Z like A, its root rotation too, and the path goes on without a jump
    np.testing.assert_allclose(rot[-1, 0], np.eye(3), atol=1e-6)
    steps = np.diff(root, axis=0)
    np.testing.assert_allclose(steps[:, [0, 2]], np.broadcast_to([0.0, 0.05], (49, 2)), atol=1e-6)
    assert root[-1, 2] == pytest.approx(0.05 * 49)


def test_join_blends_rotations_by_slerp():
    a = straight_part("a", 0.0)
    b = straight_part("b", 0.0, bend=np.pi / 2)      # B's left knee bent 90 degrees
    rot, _, _ = cp.join(a, b, scale_b=1.0, blend=10)
    angle = np.degrees(np.arccos(np.clip(rot[:, 4, 0, 0], -1, 1)))  # knee rotation about Y
    assert angle[19] == pytest.approx(0.0, abs=1e-6) and angle[30] == pytest.approx(90.0, abs=1e-4)
    ramp = angle[20:30]
    assert np.all(np.diff(ramp) > 0) and 0 < ramp[0] < 10 and 80 < ramp[-1] < 90   # smooth, monotonic
    assert ramp[5] == pytest.approx(90 * (6 / 11) ** 2 * (3 - 2 * 6 / 11), abs=1e-3)  # smoothstep weight


def test_captions_and_verb_phrases():
    assert cp.verb_phrase(["A person walks forward happily.", "x"], []) == "walks forward happily"
    assert cp.verb_phrase(["A human is walking.", "Someone is walking."], ["walk"]) == "walks"  # falls back
    assert cp.verb_phrase(["Person taking a hand shower"], []) is None
    caps = cp.composed_captions("comp0_00001", "walks forward", "waves with the left hand")
    assert caps[0] == "A person walks forward, then waves with the left hand."
    assert len(set(caps)) == 5 and all("walks forward" in c for c in caps)
    joined = " ".join(caps)
    assert caps == cp.composed_captions("comp0_00001", "walks forward", "waves with the left hand")
    assert any(k in joined for k in ("and then", "before waving", "after that", "First "))


def test_compose_into_a_built_dataset(tiny_dataset, tmp_path):
    data = tmp_path / "data"
    shutil.copytree(tiny_dataset, data)
    before = set((data / "train.txt").read_text().split())
    ids = cp.compose_dataset(data, 3, seed=0, verbose=False)
    assert ids == ["comp0_00000", "comp0_00001", "comp0_00002"]
    train = set((data / "train.txt").read_text().split())
    assert train == before | set(ids)                                  # split lists refreshed
    for cid in ids:
        meta = json.loads((data / "meta" / f"{cid}.json").read_text())
        a, b = meta["composed_from"]
        assert a in before and b in before and meta["split"] == "train"
        ma = json.loads((data / "meta" / f"{a}.json").read_text())
        mb = json.loads((data / "meta" / f"{b}.json").read_text())
        assert meta["labels"]["sequence"] == [ma["labels"]["actions"][0], mb["labels"]["actions"][0]]
        assert meta["labels"]["sequence"][0] != meta["labels"]["sequence"][1]
        ta, tb = min(ma["frames"], cp.MAX_PART_FRAMES), min(mb["frames"], cp.MAX_PART_FRAMES)
        assert meta["frames"] == ta + tb - cp.BLEND_FRAMES
        np.testing.assert_array_equal(np.load(data / "betas" / f"{cid}.npy"), np.load(data / "betas" / f"{a}.npy"))
        j = np.load(data / "new_joints" / f"{cid}.npy")
        assert j.shape == (meta["frames"], 22, 3) and np.isfinite(j).all()
        assert np.load(data / "new_joint_vecs" / f"{cid}.npy").shape == (meta["frames"] - 1, 263)
        # no jump at the transition: the pelvis moves at most as fast as in the parts
        step = np.linalg.norm(np.diff(j[:, 0, [0, 2]], axis=0), axis=1)
        assert step.max() < 0.25                                         # < 5 m/s
        caps = (data / "texts" / f"{cid}.txt").read_text().splitlines()
        assert len(caps) == 5 and caps[0].startswith("A person ") and ", then " in caps[0]
    # resumable and deterministic: a rerun writes nothing new and picks the same pairs
    assert cp.compose_dataset(data, 3, seed=0, verbose=False) == []
    counts = dict(known_actions(data))
    assert counts and all(isinstance(v, int) and v > 0 for v in counts.values())
    assert sum(counts.values()) >= len(train)


def test_compose_errors(tmp_path):
    with pytest.raises(ShapeMoveError, match="not a built dataset"):
        cp.compose_dataset(tmp_path, 3)
    (tmp_path / "meta").mkdir()
    with pytest.raises(ShapeMoveError, match="at least 2 training clips"):
        cp.compose_dataset(tmp_path, 3)
    with pytest.raises(ShapeMoveError, match="at least 1"):
        cp.compose_dataset(tmp_path, 0)


def test_only_upright_ends_are_joined(tmp_path):
    (tmp_path / "new_joints").mkdir()
    stand = np.zeros((5, 22, 3))
    stand[:, 0, 1], stand[:, 15, 1] = 0.95, 1.55          # pelvis 0.95 m, head 0.6 m above it
    lying = stand.copy()
    lying[-1, 0, 1], lying[-1, 15, 1] = 0.15, 0.2         # ends on the floor
    np.save(tmp_path / "new_joints" / "s.npy", stand)
    np.save(tmp_path / "new_joints" / "l.npy", lying)
    meta = {"measure": {"leg_length_cm": 90.0}}
    assert cp.upright(tmp_path, dict(meta, id="s"), end=True) and cp.upright(tmp_path, dict(meta, id="s"), end=False)
    assert cp.upright(tmp_path, dict(meta, id="l"), end=False) and not cp.upright(tmp_path, dict(meta, id="l"), end=True)
