"""Pace words: a gait asked to go fast, and the fastest candidates."""
import numpy as np
import pytest

from shapemove.core.generation.pace_words import RUN_OFF_SPEED, STANDING_SPEED, WANDER_SPEED, fastest, gait_speed, going, staying
from shapemove.core.plan.reader import asks_fast
from shapemove.core.plan.words import read_words


@pytest.mark.parametrize("prompt, expected", [
    ("a person walks quickly", True),
    ("a man walks briskly down the road", True),
    ("A quick sprint", True),
    ("someone runs as fast as they can", True),
    ("a soldier runs ahead at full speed", True),
    ("a person walks slowly", False),                # slow words are not enforced
    ("a person waves quickly", False),               # no gait: a hand's pace is not the root's
    ("a man walks slowly, then runs fast", False),   # both paces: none
    ("a person walks", False),
    ("an old woman hurries forward", True),          # hurrying somewhere is a walk, fast
])
def test_asks_fast_reads_a_gaits_fast_pace(prompt, expected):
    assert asks_fast(prompt) == expected


def test_gait_speed_is_the_mean_speed_along_the_path():
    f = np.zeros((20, 263), np.float32)
    f[:, 1], f[:, 2] = 0.03, 0.04          # 5 cm a frame at 20 fps: 1 m/s, whichever way it goes
    assert gait_speed(f) == pytest.approx(1.0, abs=1e-5)
    f[10:, 1:3] *= -1                     # half of it back again: still 1 m/s along the path
    assert gait_speed(f) == pytest.approx(1.0, abs=1e-5)


def test_fastest_keeps_the_fastest_third_of_the_allowed():
    speeds = np.array([0.1, 0.6, 0.9, 1.2, 1.5, 1.8, 2.1])
    everyone = np.ones(7, bool)
    # at or above the 2/3 quantile of all seven (linear rule: position 6 x 2/3 = 4, i.e. 1.5)
    assert np.flatnonzero(fastest(speeds, everyone)).tolist() == [4, 5, 6]
    # only among the candidates the travel words allowed (0.6-1.5: position 2, i.e. 1.2)
    among = np.array([False, True, True, True, True, False, False])
    assert np.flatnonzero(fastest(speeds, among)).tolist() == [3, 4]
    nobody = np.zeros(7, bool)
    assert fastest(speeds, nobody).tolist() == nobody.tolist()


def test_a_gait_asked_to_go_somewhere_sets_aside_the_candidates_that_stand_about():
    """"A person walks to the door": the 0.17 m/s candidate (0.5 m in 3 s) is set aside, unless all
    stand about; in place, a distance, counted steps, standing still or no gait keep every one."""
    from shapemove.core.plan.words import read_words

    speeds = np.array([0.17, 1.1, STANDING_SPEED, 0.05])
    everyone = np.ones(4, bool)
    assert going(read_words("a person walks to the door"), speeds, everyone).tolist() == [False, True, True, False]
    assert going(read_words("she sneaks forward"), speeds, everyone).tolist() == [False, True, True, False]
    assert going(read_words("a person walks"), np.array([0.1, 0.2, 0.05, 0.0]), everyone).tolist() == [True] * 4
    for prompt in ("a person jogs in place", "a man walks 3 metres forward", "she takes three steps forward",
                   "a person stands still", "a man waves"):
        assert going(read_words(prompt), speeds, everyone).tolist() == [True] * 4, prompt


def test_an_exercise_or_a_gesture_asked_with_no_travel_does_not_walk_off():
    """"twists her torso side to side" chose a sample walking sideways 4.8 m; "swings his arms in
    circles" a take walking 5 m. Candidates as fast as WANDER_SPEED are set aside when one is slower;
    a gait, travel words, a course, an action of another group, or none slower: all kept."""
    everyone = np.ones(4, bool)
    speeds = np.array([1.2, 0.1, WANDER_SPEED, 0.3])
    assert staying(read_words("a woman twists her torso side to side"), speeds, everyone).tolist() == \
        [False, True, False, True]
    assert staying(read_words("a man swings his arms in circles"), speeds, everyone).tolist() == [False, True, False, True]
    assert staying(read_words("someone waves"), speeds, everyone).tolist() == [False, True, False, True]
    assert staying(read_words("a man waves"), np.full(4, 1.0), everyone).tolist() == [True] * 4   # none slower
    for prompt in ("an old man sits down slowly", "a woman lies down", "he gets up"):   # a change of posture
        assert staying(read_words(prompt), speeds, everyone).tolist() == [False, True, False, True], prompt
    for prompt in ("a man walks and waves", "she waves while walking forward", "a woman dances",
                   "the player kicks the ball", "a man does arm circles while jogging", "someone jumps forward"):
        assert staying(read_words(prompt), speeds, everyone).tolist() == [True] * 4, prompt
    fast = np.array([3.3, 0.4, RUN_OFF_SPEED, 1.2])   # a dance that runs off 13 m in 4 s is set aside
    for prompt in ("the robot busts a move", "a woman dances", "the player kicks the ball", "a kid does a cartwheel"):
        assert staying(read_words(prompt), fast, everyone).tolist() == [False, True, False, True], prompt
    for prompt in ("a man walks and waves", "a woman runs", "she dances forward", "someone jumps forward"):   # a gait, travel
        assert staying(read_words(prompt), fast, everyone).tolist() == [True] * 4, prompt


def test_the_picker_takes_a_fast_walk_over_the_tmas_favourite():
    """Six captured walks from the shipped memory, decoded on the mean body (0.56-1.35 m/s): the
    TMA alone prefers a 0.65 m/s walk for "walks quickly"; for "walks slowly" the TMA chooses."""
    from shapemove.core.generation.decode import decode_features
    from shapemove.core.generation.generate import Generator

    gen = Generator("weights/default")
    memory = gen.t5.memory
    walks = [i for i, _ in memory.clips_of_action("walk")][:12:2]
    feats = [decode_features(list(memory.clip_tokens[i]), gen.vae, np.zeros(10, np.float32)).numpy() for i in walks]
    speeds = np.array([gait_speed(f) for f in feats])
    fits = speeds >= np.quantile(speeds, 2 / 3)
    scores = gen.picker.scores("a person walks quickly", feats)
    assert not fits[int(np.argmax(scores))], "the TMA alone should prefer a slower walk here"
    best = gen.picker.pick("a person walks quickly", feats)
    assert fits[best] and scores[best] == scores[fits].max() and speeds[best] > 1.0
    slow = gen.picker.scores("a person walks slowly", feats)
    assert gen.picker.pick("a person walks slowly", feats) == int(np.argmax(slow))


def test_pace_checks_speed_is_the_pelvis_along_its_path():
    from shapemove.core.eval.gait import mean_speed

    t = np.arange(41) / 20.0                                    # 2 s at 20 fps
    joints = np.zeros((41, 22, 3))
    joints[:, 0, 0] = np.where(t <= 1, 1.5 * t, 1.5 * (2 - t))  # 1.5 m/s out, 1.5 m/s back
    joints[:, 0, 1] = 0.9 + 0.05 * np.sin(8 * t)                # bobbing does not count
    assert mean_speed(joints, 20.0) == pytest.approx(1.5, abs=1e-9)


def test_the_pace_sets_ask_one_gait_slow_plain_and_fast():
    import json
    from pathlib import Path

    from shapemove.core.data.actions import action_spans
    from shapemove.core.plan.part_prompts import LEGS

    root = Path(__file__).resolve().parents[1]
    for name in ("tuning_pace.json", "heldout_pace_blind.json"):
        rows = json.loads((root / "configs" / name).read_text())["rows"]
        assert len(rows) >= 10
        for row in rows:
            assert len(row) == 3 and any(sp[2] in LEGS for sp in action_spans(row[1])), row
            assert not asks_fast(row[0]) and not asks_fast(row[1]), row
    # on the tuning set, every fast prompt reads fast ("hurries forward" too: a walk, fast)
    rows = json.loads((root / "configs" / "tuning_pace.json").read_text())["rows"]
    assert [r[2] for r in rows if not asks_fast(r[2])] == []


@pytest.mark.parametrize("prompt, expected", [
    ("a person walks slowly", True),
    ("the guard marches slowly", True),
    ("a man strolls at a leisurely pace down the road", True),
    ("a woman jogs slowly", False),              # a flight phase: shorter strides instead
    ("a person walks slowly, then runs", False),  # a gait with flight beside it
    ("a person walks", False),
    ("a person waves slowly", False),
])
def test_asks_slow_steps_reads_a_stepping_gaits_slow_pace(prompt, expected):
    from shapemove.core.plan.reader import asks_slow_steps

    assert asks_slow_steps(prompt) == expected


@pytest.mark.parametrize("prompt, expected", [
    ("a woman jogs slowly", True),
    ("a man jogs at an easy pace", True),
    ("a person walks slowly, then runs", True),   # a flight phase among the gaits: strides, not time
    ("a person walks slowly", False),             # played slower instead
    ("a woman jogs", False),
    ("a woman jogs slowly, then fast", False),    # both paces: no pace
    ("someone waves slowly", False),
])
def test_asks_slow_flight_reads_a_jog_or_runs_slow_pace(prompt, expected):
    from shapemove.core.plan.reader import asks_slow_flight

    assert asks_slow_flight(prompt) == expected


def test_slow_motion_plays_a_walk_at_the_slow_speed_over_the_same_length():
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.pace_words import SLOW_SPEED
    from shapemove.core.generation.slow_steps import slow_motion

    gen = Generator("weights/default")
    walk = gen.generate_batch([Request("a person walks forward", seconds=4.0, seed=0)])[0]
    assert slow_motion(walk, gen.body, read_words("a person walks forward")) is walk
    slow = slow_motion(walk, gen.body, read_words("a person walks forward slowly"))
    assert slow.num_frames == walk.num_frames and slow.tokens is None   # an edit: no tokens kept
    # the slowed walk covers what the walk covered in its first SLOW_SPEED of the time
    keep = int(round(walk.num_frames * SLOW_SPEED))
    path = lambda j: np.linalg.norm(np.diff(j[:, 0, [0, 2]], axis=0), axis=1).sum()
    assert path(slow.joints) == pytest.approx(path(walk.joints[:keep]), rel=0.03)
    assert path(slow.joints) < 0.85 * path(walk.joints)
    # planted again: the lowest foot joint stays on the walk's floor
    feet = [7, 8, 10, 11]
    assert abs(slow.joints[:, feet, 1].min() - walk.joints[:, feet, 1].min()) < 0.01
    assert slow.features is not None and len(slow.features) == slow.num_frames - 1


def test_slow_motion_gives_a_jog_shorter_strides_at_the_same_cadence():
    """A jog asked slowly is not played slower (its flights would hang in the air): the same frames,
    the same flights, strides SLOW_SPEED as long, the feet planted again."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.pace_words import SLOW_SPEED
    from shapemove.core.generation.slow_steps import slow_motion

    gen = Generator("weights/default")
    jog = gen.generate_batch([Request("a person jogs forward", seconds=4.0, seed=0)])[0]
    slow = slow_motion(jog, gen.body, read_words("a person jogs forward slowly"))
    assert slow.num_frames == jog.num_frames and slow.tokens is None
    path = lambda j: np.linalg.norm(np.diff(j[:, 0, [0, 2]], axis=0), axis=1).sum()  # noqa: E731
    assert path(jog.joints) > 4.0 and path(slow.joints) == pytest.approx(SLOW_SPEED * path(jog.joints), rel=0.05)
    # the flights stay where they were: the frames with no foot planted
    flight = lambda m: ~m.contacts.astype(bool).any(1)  # noqa: E731
    assert flight(jog).sum() >= 8 and (flight(slow) == flight(jog)).mean() > 0.9
    slide = []
    for k, j in ((2, 10), (3, 11)):   # the balls of the feet where planted
        on = (slow.contacts[1:, k] > 0) & (slow.contacts[:-1, k] > 0)
        slide += list(np.linalg.norm(np.diff(slow.joints[:, j, [0, 2]], axis=0), axis=1)[on])
    assert len(slide) > 10 and np.mean(slide) < 0.002



def test_two_things_at_once_asked_slowly_go_slower_and_on():
    """"walks slowly while waving": the composed motion is played slower (a jog: shorter strides),
    and a jog asked slowly is never a captured one-cycle jog held still for the rest (DeepMimic's
    jog cycle loops on its stride)."""
    from shapemove.core.generation.generate import Request
    from shapemove.core.generation.loaded_generator import loaded_generator

    gen = loaded_generator(None)

    def speed(prompt):
        m = gen.generate_batch([Request(prompt, seconds=4.0, seed=0)])[0]
        return float(np.linalg.norm(m.transl[-1, [0, 2]] - m.transl[0, [0, 2]])) / 4.0, m

    walk, _ = speed("a man walks while waving")
    slow_walk, m = speed("a man walks slowly while waving")
    assert slow_walk < 0.9 * walk and m.part_prompts == ("a man walks slowly", "a person waving")
    jog, _ = speed("a woman jogs along, waving")
    slow_jog, m = speed("a woman jogs slowly, waving")
    assert 0.6 * jog < slow_jog < 0.9 * jog
    last = float(np.linalg.norm(m.transl[-1, [0, 2]] - m.transl[-21, [0, 2]]))   # the last second
    assert last > 0.7 * slow_jog and not any("is held" in n for n in m.notes)   # jogs on to the end
