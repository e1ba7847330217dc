"""Motions put together by body part (core/generation/part_compose.py, parts.py): the arms of one
track on another's chest, the named side moving most, and a by-parts motion that re-decodes,
saves and loads as itself."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.generation.part_compose import (ARM_JOINTS, CHEST, GIRDLE, LIMBS, chest_frames, compose_arms,
                                                     heading_frames, mirror_track, needs_mirror, side_activity)

pytestmark = pytest.mark.usefixtures("one_thread")


def _track(seed: int, T: int = 40) -> np.ndarray:
    """A body-like (T,22,3) track: SMPL-ish rest joints with noise that moves over time."""
    rng = np.random.default_rng(seed)
    rest = np.zeros((22, 3))
    rest[:, 1] = np.linspace(0.0, 1.6, 22)
    rest[[1, 4, 7, 10, 13, 16, 18, 20], 0] = 0.15     # left side at +x
    rest[[2, 5, 8, 11, 14, 17, 19, 21], 0] = -0.15
    rest[3, 1], rest[CHEST, 1] = 1.0, 1.3
    rest[[3, CHEST], 0] = 0.0
    wob = np.cumsum(rng.normal(0, 0.01, (T, 22, 3)), axis=0)
    return rest[None] + wob


def _turn(j: np.ndarray, deg: float, shift) -> np.ndarray:
    a = np.radians(deg)
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    return j @ R.T + np.asarray(shift)


def test_compose_keeps_the_legs_girdle_in_the_chest_frame_limbs_in_the_heading_frame():
    legs, arms = _track(0), _track(1)
    out = compose_arms(legs, arms)
    other = [i for i in range(22) if i not in ARM_JOINTS]
    assert np.array_equal(out[:, other], legs[:, other])
    # collars and shoulders relative to the chest, in the chest's frame, are the arms track's own
    rel = lambda j, idx: np.einsum("tji,tkj->tki", chest_frames(j), j[:, idx] - j[:, CHEST:CHEST + 1])  # noqa: E731
    assert np.allclose(rel(out, GIRDLE), rel(arms, GIRDLE), atol=1e-9)
    # each upper arm and forearm keeps its direction in the heading frame, and its length
    for joint, parent in LIMBS:
        seg = lambda j: np.einsum("tji,tj->ti", heading_frames(j), j[:, joint] - j[:, parent])  # noqa: E731
        got = np.einsum("tji,tj->ti", heading_frames(legs), out[:, joint] - out[:, parent])
        assert np.allclose(got, seg(arms), atol=1e-9)
    # where the arms track stands and which way it faces does not matter
    assert np.allclose(compose_arms(legs, _turn(arms, 73.0, [3.0, 0.2, -1.0])), out, atol=1e-9)
    # a track composed with itself is itself
    assert np.allclose(compose_arms(legs, legs), legs, atol=1e-9)


def test_a_raised_hand_stays_raised_on_a_body_leaning_forward():
    """Hand-derived: the arms track stands upright with the left arm straight up; the legs track
    is the same body leaning 30 degrees forward (a runner). The composed left elbow and wrist are
    straight above the shoulder (world vertical); carried in the chest's frame they tipped 30
    degrees forward with the torso."""
    T = 12
    stand = np.repeat(_track(0, 1)[:1], T, axis=0)
    stand[..., 2] = 0.0                                      # a flat body in the x-y plane, facing +Z
    stand[:, [13, 14, 16, 17, 18, 19, 20, 21], 1] = 1.4     # collars, shoulders, elbows, wrists level
    stand[:, 16, 0], stand[:, 18, 0], stand[:, 20, 0] = 0.2, 0.2, 0.2
    stand[:, 18, 1], stand[:, 20, 1] = 1.7, 2.0             # left upper arm and forearm straight up
    a = np.radians(30.0)
    R = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])  # lean toward +Z
    lean = (stand - stand[:, :1]) @ R.T + stand[:, :1]
    out = compose_arms(lean, stand)
    up = out[:, 20] - out[:, 16]
    assert np.allclose(up[:, [0, 2]], 0.0, atol=1e-9) and np.allclose(up[:, 1], 0.6, atol=1e-9)
    # the left shoulder rides the leaning chest: where the leaning body's own shoulder is
    assert np.allclose(out[:, 16], lean[:, 16], atol=1e-9)


def test_compose_refuses_tracks_of_different_lengths():
    with pytest.raises(ShapeMoveError, match="as long"):
        compose_arms(_track(0, 40), _track(1, 39))
    with pytest.raises(ShapeMoveError, match="joints"):
        compose_arms(np.zeros((40, 24, 3)), _track(1))


def test_side_activity_and_the_mirror():
    j = _track(2)
    t = np.arange(len(j))
    j[:, 20, 1] += 0.3 * np.sin(t / 3.0)            # the left wrist waves
    left, right = side_activity(j, "hand")
    assert left > right + 1.0
    assert not needs_mirror(j, "left", "hand") and needs_mirror(j, "right", "hand")
    c = np.zeros((len(j), 4), np.uint8)
    c[:, 0] = 1                                     # left heel down
    mj, mc = mirror_track(j, c)
    assert needs_mirror(mj, "left", "hand") and not needs_mirror(mj, "right", "hand")
    assert side_activity(mj, "hand") == pytest.approx((right, left))
    assert mc[:, 1].all() and not mc[:, 0].any()
    jj, cc = mirror_track(mj, mc)
    assert np.allclose(jj, j) and np.array_equal(cc, c)
    with pytest.raises(ShapeMoveError, match="part"):
        side_activity(j, "head")
    with pytest.raises(ShapeMoveError, match="side"):
        needs_mirror(j, "up", "hand")


@pytest.fixture(scope="module")
def gen():
    from shapemove.core.generation.generate import Generator

    gen = Generator(None)
    gen.set_captured(False)   # composition by parts is measured against the model's own whole motions
    return gen


def test_two_things_at_once_are_composed_and_redecode_as_themselves(gen, tmp_path):
    from shapemove.core.generation.generate import Request
    from shapemove.core.scene.motion_file import check_consistent, load_motion, save_motion

    text = "a person walks forward while waving the left hand"
    m = gen.generate_batch([Request(text, seconds=3, seed=0)])[0]
    assert m.part_prompts == ("a person walks forward", "a person waving the left hand")
    assert m.arms_tokens is not None and len(m.arms_tokens) == len(m.tokens) == 15
    check_consistent(gen.body, m)
    # the left hand is the one that moves (mirrored when the sample waved the right one)
    left, right = side_activity(m.joints, "hand")
    assert left > right
    # the legs are the legs prompt's own: the same seed's walk, asked for as that action (the
    # captured walks of the memory, action_clips.py), has the same root path
    whole = gen.generate_batch([Request("a person walks forward", seconds=3, seed=0, action="walk")])[0]
    assert np.abs(m.joints[:, 0] - whole.joints[:, 0]).max() < 0.02
    # saved and loaded, then re-decoded for the same body: the same motion
    path = save_motion(tmp_path / "two.npz", m)
    back = load_motion(path)
    assert np.array_equal(back.arms_tokens, m.arms_tokens) and back.arms_mirrored == m.arms_mirrored
    again = gen.redecode(back, back.betas)
    assert np.abs(again.joints - m.joints).max() < 1e-3
    # without parts the same prompt is one sample of the whole sentence
    plain = gen.generate_batch([Request(text, seconds=3, seed=0, by_parts=False)])[0]
    assert plain.arms_tokens is None and plain.part_prompts is None


def test_captured_clips_left_to_the_model_last_at_least_four_seconds(gen):
    """The README's demo prompt, no length asked: its jog comes from a captured clip of 8 codes
    (a 1.6 s DeepMimic jog cycle), which is played again to 4 s instead of delivered as 1.6 s, at
    the jog's typical pace."""
    from shapemove.core.generation.action_clips import UNASKED_SECONDS
    from shapemove.core.generation.generate import Request

    from shapemove.core.generation.typical_pace import body_speed
    from shapemove.core.motion.root_speed import mean_speed

    m = gen.generate_batch([Request("a person jogs forward and waves", seed=0)])[0]
    assert m.part_prompts == ("a person jogs forward", "a person waves") and m.retrieved_clips
    assert len(m.joints) == round(UNASKED_SECONDS * 20) == 80
    # the legs' jog brought down toward the jog's typical pace (samples jog at 2.1-2.4 m/s, 1.56
    # typical; by at most 1.5x): an edit, so the composed motion keeps no codes
    typical = body_speed(gen.typical_speeds["jog"], gen.body, m.betas)
    assert 0.8 * typical < mean_speed(m.joints, m.fps) < 1.15 * typical
    assert m.tokens is None or len(m.tokens) == len(m.arms_tokens) == 20


def test_a_named_side_moves_most(gen):
    from shapemove.core.generation.generate import Request

    for side in ("left", "right"):
        m = gen.generate_batch([Request(f"a person kicks with the {side} foot", seconds=3, seed=1)])[0]
        left, right = side_activity(m.joints, "foot")
        assert (left > right) == (side == "left"), (side, left, right)
    m = gen.generate_batch([Request("a person kicks with the left foot", seconds=3, seed=1, by_parts=False)])[0]
    assert not m.mirrored


def test_bad_by_parts_fields_are_refused(gen, tmp_path):
    import dataclasses

    from shapemove.core.generation.generate import Request
    from shapemove.core.scene.motion_file import load_motion, save_motion

    m = gen.generate_batch([Request("a person kicks with the left foot", seconds=2, seed=0)])[0]
    with pytest.raises(ShapeMoveError, match="arms_tokens"):
        save_motion(tmp_path / "bad.npz", dataclasses.replace(m, arms_tokens=np.zeros((2, 2), np.int16)))
    with pytest.raises(ShapeMoveError, match="mirrored"):
        save_motion(tmp_path / "bad.npz", dataclasses.replace(m, tokens=None, mirrored=True))
    path = save_motion(tmp_path / "ok.npz", m)
    data = dict(np.load(path))
    data["mirrored"] = np.array([1, 0], np.uint8)
    np.savez(tmp_path / "bad2.npz", **data)
    with pytest.raises(ShapeMoveError, match="mirrored"):
        load_motion(tmp_path / "bad2.npz")


def test_clauses_the_patterns_miss_are_named_by_the_nearest_caption(gen):
    from shapemove.core.plan.part_prompts import clauses, plan_parts
    from shapemove.core.generation.parts import plan_of

    text = "a man marches, swinging his right arm overhead"
    assert clauses(text) == ["a man marches", "swinging his right arm overhead"]
    assert plan_parts(text) is None                  # "swinging ... overhead" is none of the action patterns
    plan, side = plan_of(text, gen)
    assert (plan.legs_prompt, plan.arms_prompt) == ("a man marches", "a man swinging his right arm overhead")
    assert (plan.legs_action, plan.arms_action) == ("march", "raise hand") and side is None
    assert plan.arms_side == ("right", "hand")
    both = plan_of("a man tiptoes and circles his arms", gen)[0]   # the arms' circles named: two things
    assert (both.legs_action, both.arms_action) == ("sneak", "arm circles")
    # single actions stay whole: no part named by the patterns, a subject alone, "as fast as"
    for single in ("A person walking with a hurt right leg",
                   "A man running as fast as he can", "he walks to the door and opens it",
                   "A zombie shambling toward the camera, arms out",
                   "A person raises the left hand slowly, like an elderly person.",   # a style, not a walk
                   "A woman is raising both hands energetically, with youthful vigour."):
        assert plan_of(single, gen)[0] is None, single


def test_the_generate_job_says_what_was_composed(tmp_path):
    from shapemove.core.worker import jobs_shapemove
    from shapemove.core.worker.client import InProcessRunner

    runner = InProcessRunner(jobs_shapemove.register({}))
    try:
        text = "a person walks forward while waving the left hand"
        r = runner.call("generate", {"prompt": text, "seconds": 2, "out": str(tmp_path / "a.npz")})
        assert r["parts"][0] == ("Two things at once: legs 'a person walks forward', "
                                 "arms 'a person waving the left hand'")
        r = runner.call("generate", {"prompt": text, "seconds": 2, "by_parts": False, "out": str(tmp_path / "b.npz")})
        assert r["parts"] == []
        with pytest.raises(ShapeMoveError, match="'by_parts' must be bool"):
            runner.call("generate", {"prompt": text, "by_parts": "yes", "out": str(tmp_path / "c.npz")})
    finally:
        runner.stop()
