"""Travel words: which way a prompt sends the body, and the candidates that go against it."""
import numpy as np
import pytest

from shapemove.core.generation.travel_words import SLACK, body_frame_travel, obeys
from shapemove.core.generation.travel_words import allowed as _allowed
from shapemove.core.plan.reader import Travel, travel_of


def allowed(prompt, feats):
    return _allowed(travel_of(prompt), feats)


@pytest.mark.parametrize("prompt, expected", [
    ("A tall heavy man trudges forward", Travel(forward=1)),
    ("person strutting confidently toward the camera", Travel(forward=1)),
    ("The hiker paces ahead at a steady clip", Travel(forward=1)),
    ("A person backs up step by step", Travel(forward=-1)),
    ("the character retreats, walking in reverse", Travel(forward=-1)),
    ("walks forward and backward", Travel()),                      # both ways: no direction
    ("she takes a quick step back", Travel(forward=-1)),
    ("a boxer steps back and forth", Travel()),
    ("A man shuffles to his left", Travel(side=1)),
    ("crab walk sideways to the right", Travel(side=-1)),
    ("the goalkeeper side-steps to the right along the line", Travel(side=-1)),
    ("steps to the left, then steps to the right", Travel()),      # both sides: none
    ("a man walks sideways", Travel(sideways=True)),
    ("toy soldier marching in place", Travel(in_place=True)),
    ("twirl around on the spot", Travel(in_place=True)),
    ("a boy jumps up and down", Travel(in_place=True)),           # a jump that stays: not a long jump
    ("she jumps straight up", Travel(in_place=True)),
    ("a big vertical jump", Travel(in_place=True)),
    ("a man walks up and down the hall", Travel()),                # a walk's up and down is a course
    ("waves to his left", Travel()),                               # a side, but no going
    ("A golfer swings to the left", Travel()),
    ("a person jumps and waves", Travel()),
    ("a woman circles her arms backwards", Travel()),              # the way the arms go, not the body
    ("he swings his arms forward", Travel()),
    ("she walks backwards, circling her arms", Travel(forward=-1)),
    ("a woman does a cartwheel to the right", Travel(side=-1)), ("he rolls to the left", Travel(side=1)),
    ("a man turns right", Travel(in_place=True)),                  # a turn alone: on the spot
])
def test_travel_of_reads_the_words(prompt, expected):
    assert travel_of(prompt) == expected


def _clip(forward_per_frame: float, left_per_frame: float, frames: int = 40) -> np.ndarray:
    f = np.zeros((frames, 263), np.float32)
    f[:, 2], f[:, 1] = forward_per_frame, left_per_frame
    return f


def test_body_frame_travel_sums_each_frames_step():
    fwd, left = body_frame_travel(_clip(0.03, -0.01))
    assert fwd == pytest.approx(1.2, abs=1e-5) and left == pytest.approx(-0.4, abs=1e-5)


def test_a_word_rules_out_only_travel_against_it_beyond_the_slack():
    assert SLACK == 0.5
    forward = Travel(forward=1)
    assert obeys(forward, _clip(0.0, 0.0))                  # a punch "forward" need not travel
    assert obeys(forward, _clip(-0.012, 0.0))               # 0.48 m back: within the slack
    assert not obeys(forward, _clip(-0.013, 0.0))           # 0.52 m back
    assert not obeys(Travel(forward=-1), _clip(0.05, 0.0))  # 2 m forward for "backwards"
    left = Travel(side=1)
    assert obeys(left, _clip(0.0, 0.02))                    # 0.8 m to the body's left (+X)
    assert not obeys(left, _clip(0.0, 0.01))                # 0.4 m: not enough to the left
    assert not obeys(left, _clip(0.0, -0.02))               # to the right
    sideways = Travel(sideways=True)
    assert obeys(sideways, _clip(0.01, -0.02)) and not obeys(sideways, _clip(0.03, 0.02))
    in_place = Travel(in_place=True)
    assert obeys(in_place, _clip(0.012, 0.0)) and not obeys(in_place, _clip(0.02, 0.0))  # 0.48 m; 0.8 m
    assert not obeys(in_place, _clip(0.0, -0.013))          # 0.52 m to the side (a hop of HDM05: 1 m)


def test_allowed_sets_aside_the_contrary_and_keeps_all_when_none_obey():
    feats = [_clip(-0.09, 0.0), _clip(0.04, 0.0), _clip(0.0, 0.0)]
    assert allowed("a man trudges forward", feats).tolist() == [False, True, True]
    assert allowed("a man walks backwards", feats).tolist() == [True, False, True]
    assert allowed("a man walks", feats).tolist() == [True, True, True]
    assert allowed("a man steps to his left", feats).tolist() == [True, True, True]   # none goes left


def test_the_picker_sets_aside_the_tmas_favourite_when_it_walks_backward():
    """The blind paraphrase that showed it: the TMA alone chose a captured walk backward for
    "a tall heavy man trudges forward". Here the shipped TMA scores the memory's walk backward
    above its forward walk, and the picker takes the forward one."""
    from shapemove.core.generation.decode import decode_features
    from shapemove.core.generation.generate import Generator

    gen = Generator("weights/default")
    memory = gen.t5.memory
    prompt = "A tall heavy man trudges forward"
    back = [i for i, _ in memory.clips_of_action("walk backward")]
    walks = [i for i, _ in memory.clips_of_action("walk")]
    betas = np.zeros(10, np.float32)
    feats = [decode_features(list(memory.clip_tokens[i]), gen.vae, betas).numpy() for i in back[:4] + walks[:4]]
    scores = gen.picker.scores(prompt, feats)
    fwd = np.array([body_frame_travel(f)[0] for f in feats])
    assert (fwd[:4] < -SLACK).all() and (fwd[4:] > SLACK).all(), fwd
    assert int(np.argmax(scores)) < 4, "the TMA alone should prefer a walk backward here"
    best = gen.picker.pick(prompt, feats)   # scored with the asked action as the captions say it, half each
    both = (scores + gen.picker.scores("a person walks", feats)) / 2
    assert best >= 4 and best == 4 + int(np.argmax(both[4:]))


def test_a_gait_asked_backwards_is_a_walk_backward_with_a_note():
    """No capture runs, jogs or marches backwards, and every take and sample goes forward: "a woman
    runs backwards" ran 7.5 m forward, "a man jogs backwards" stood about. The walk backward's takes
    are offered for them (seed 0, 4 s), and the motion says so; a walk backward is itself."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.travel_words import backward_taken
    from shapemove.core.plan.words import read_words

    assert backward_taken(read_words("a woman runs backwards"), "run") == "walk backward"
    assert backward_taken(read_words("a man marches backwards"), "march") == "walk backward"
    assert backward_taken(read_words("a man walks backwards"), "walk backward") is None
    assert backward_taken(read_words("a woman runs forward"), "run") is None
    assert backward_taken(read_words("she kicks backwards"), "kick") is None          # no gait
    gen = Generator(None)
    for prompt, verb in (("a woman runs backwards", "runs"), ("a man jogs backwards", "jogs")):
        m = gen.generate_batch([Request(prompt, seed=0, seconds=4)])[0]
        z = m.joints[:, 0, 2]
        assert z[-1] - z[0] < -2.0, (prompt, z[-1] - z[0])      # it goes backwards (it faces +Z at the start)
        assert f"no capture {verb} backwards: a walk backward is played" in m.notes, m.notes


def test_hopping_on_the_spot_stays_on_the_spot(openbody):
    """With the default model: HDM05's hops on both feet go about a metre forward each; "a person
    hops on the spot" (4 s, seed 0) played one (0.9 m forward, then standing) while the in-place
    tolerance was 1 m; now the motion leaves the floor and stays within 0.5 m."""
    from shapemove.core.generation.generate import Generator, Request

    m = Generator(None, body=openbody).generate_batch([Request("a person hops on the spot", seconds=4, seed=0)])[0]
    root = m.joints[:, 0]
    assert np.ptp(root[:, [0, 2]], axis=0).max() < 0.5
    feet = m.joints[:, [7, 8, 10, 11], 1].min(1)
    assert feet.max() > 0.15                                        # off the floor: a hop, not a stand


def test_jumping_up_and_down_does_not_jump_away(openbody):
    """With the default model: "a boy jumps up and down" (4 s, seed 0) played CMU's far jump 105_40,
    1.8 m forward, as "jumps straight up" played a jump 0.6 m forward; read as staying, a jump in
    place plays and leaves the floor."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None, body=openbody)
    for prompt in ("a boy jumps up and down", "she jumps straight up"):
        m = gen.generate_batch([Request(prompt, seconds=4, seed=0)])[0]
        assert np.linalg.norm(m.joints[-1, 0, [0, 2]] - m.joints[0, 0, [0, 2]]) < 0.3, prompt
        feet = m.joints[:, [7, 8, 10, 11], 1].min(1)
        assert feet.max() - feet.min() > 0.15, prompt               # off the floor: a jump


def test_a_hop_asked_on_the_spot_at_the_models_length_is_brought_back_to_the_spot(openbody):
    """At the model's own length the candidates are as long as each sample or take, and none of
    "a person hops on the spot" (seed 0) stays within 0.5 m: every one competes and an HDM05 hop that
    lands 1.0 m forward was played. The words keep the body on the spot as they keep a gait
    (``on_the_spot.py``): its stride is shortened to 0.5 m of travel."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.track import travel

    m = Generator(None, body=openbody).generate_batch([Request("a person hops on the spot", seed=0)])[0]
    assert float(travel(m.joints)[-1]) <= 0.55
    assert np.ptp(m.joints[:, 0, [0, 2]], axis=0).max() < 0.7
    assert m.joints[:, [7, 8, 10, 11], 1].min(1).max() > 0.15     # it still leaves the floor


def test_a_sidestep_plays_a_take_that_goes_to_the_side():
    """The data's sidesteps are Bandai's walks to the left or right, most going forward two to four
    times as far as to the side; the plain one (walk-left, normal) 0.47 leg lengths a second to the
    side and 1.39 forward. A take that goes to the side at least as far as forward competes where
    any does (3 of the library's 21), whatever its manner: the plain one "walked ahead, veering"."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.eval.part_judge import legs_descriptor
    from shapemove.core.generation.travel_words import goes_sideways

    assert goes_sideways(_clip(0.01, -0.02)) and not goes_sideways(_clip(0.03, 0.02))
    gen = Generator(None)
    takes = [i for i in range(len(gen.pool)) if gen.pool.actions[i] == "sidestep"]
    aside = [i for i in takes if gen.pool.sideways(i)]
    assert len(takes) >= 10 and 1 <= len(aside) <= len(takes) // 3
    assert "dataset-1_walk-left_normal_001" not in {gen.pool.ids[i] for i in aside}
    for seed in range(2):
        m = gen.generate_batch([Request("a man steps to the side", seed=seed, seconds=3)])[0]
        assert any(gen.pool.ids[i] in m.provenance for i in aside), m.provenance
        fwd, side = legs_descriptor(np.asarray(m.joints)[:, :22])["root"][:2]   # leg lengths a second, body frame
        assert abs(side) >= abs(fwd) > 0.2, (fwd, side)                           # the plain take's: 1.39 / 0.47


def test_a_take_going_the_other_side_is_offered_as_its_mirror_image():
    """Hand-derived: 0.9 m to the left (0.0225 m a frame, 40 frames) is the other side for "to the
    right" (beyond the 0.5 m slack), not for "to the left" or no side; the captured cartwheel goes
    0.9 m to its left, and "a cartwheel to the right" plays its mirror image."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.travel_words import other_side
    from shapemove.core.motion.features import motion_features

    left = _clip(0.0, 0.0225)
    assert other_side(Travel(side=-1), left) and not other_side(Travel(side=1), left)
    assert not other_side(Travel(), left) and not other_side(Travel(side=-1), _clip(0.0, 0.01))
    gen = Generator(None)
    m = gen.generate_batch([Request("a woman does a cartwheel to the right", seed=0)])[0]
    assert m.provenance.endswith("mirrored") and body_frame_travel(motion_features(m))[1] < -0.5
