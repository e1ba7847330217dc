"""Stopping (core/generation/stop_words.py): "takes three steps forward and stops" walks three steps
and then stands, with the model's own standing code; the tokens are kept, so a new body stops too."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.stop_words import distance_cut, standing_after, stop_cut
from shapemove.core.plan.reader import asked_distance, stop_request


@pytest.mark.parametrize("text, want", [
    ("a man takes three steps forward and stops", ("a man takes three steps forward", 3)),
    ("a person walks forward and then stops.", ("a person walks forward", None)),
    ("she jogs, then comes to a stop", ("she jogs", None)),
    ("a woman walks a few steps and stands still", ("a woman walks a few steps", 3)),
    ("a man walks 4 steps then halts", ("a man walks 4 steps", 4)),
    ("he takes a step and stops", ("he takes a step", 1)),
    ("A man walks forward and stops walking", ("A man walks forward", None)),
    ("someone runs without stopping", None),       # negated
    ("a person stops", None),                      # no gait to stop
    ("she waves and stops", None),                 # a gesture, not a gait
    ("a person walks forward", None),
    ("a man takes three steps forward", ("a man takes three steps forward", 3)),   # a count alone stops too
    ("she takes a step back.", ("she takes a step back", 1)),
    ("a dancer takes two steps and spins", None),  # another action beside the steps
    ("a man steps to the side repeatedly", None),  # "a man steps": no count
    ("someone runs at a quick pace", None),        # a pace, not a step
    ("a man walks 3 metres forward", ("a man walks forward", None)),      # a distance: sampled without it
    ("she runs ten meters and stops", ("she runs", None)),
    ("a woman walks 2 m forward, waving", ("a woman walks forward, waving", None)),   # a gesture stops with it
    ("a man walks 3 metres and spins", None),      # another action after the distance
    ("a six foot man walks forward", None),        # a height, not a distance
    ("a man runs and stops suddenly", ("a man runs", None)),      # how it stops, said after
    ("she jogs and comes to a sudden halt", ("she jogs", None)),
    ("he walks and stops dead in his tracks", ("he walks", None)),
    ("a woman walks quickly to the bus stop", None), ("he runs to the next stop", None),   # a stop as a place
])
def test_the_words_that_stop_a_gait(text, want):
    assert stop_request(text) == want


def test_stop_codes_cut_after_the_counted_strike():
    contacts = np.zeros((40, 4), np.uint8)
    for a in (0, 9, 21, 30):                        # frame 0 is no strike: strikes at 9, 21, 30
        contacts[a:a + 5, (a // 9) % 2] = 1
    codes = list(range(10))
    assert stop_cut(contacts, 2, 10, 4) == 7                                       # strike 21 -> code 5, +1
    assert stop_cut(contacts, 3, 10, 4) == 9 and stop_cut(contacts, 1, 10, 4) == 4
    assert stop_cut(contacts, None, 10, 4) == 5 and stop_cut(contacts, None, 1, 4) == 1   # half the length
    assert stop_cut(contacts, 4, 10, 4) is None                                    # fewer strikes than counted
    assert standing_after(codes, 7, 99) == [0, 1, 2, 3, 4, 5, 6] + [99] * 3
    assert standing_after(codes, 7, 99, stand=8) == [0, 1, 2, 3, 4, 5, 6] + [99] * 8   # the model's length


@pytest.mark.parametrize("text, metres", [
    ("a man walks 3 metres forward", 3.0), ("someone jogs 20 feet", 6.096), ("she runs ten meters", 10.0),
    ("walk 2.5 m to the left", 2.5), ("a soldier marches 200 yards", None),       # 183 m: over MAX_METRES
    ("a soldier marches 50 yards", 45.72), ("a man six feet tall walks 2 m", 2.0), ("a 2 m tall woman runs", None),
    ("a man jumps 2 metres", None),                # no gait
])
def test_the_distance_a_gait_is_asked_to_go(text, metres):
    got = asked_distance(text)
    assert (got is None) if metres is None else got == pytest.approx(metres)


def test_the_distance_cut_is_the_code_that_gets_there():
    """A root going 1 m/s along +Z at 20 fps reaches 2 m (less REACH_SLACK, 0.1 m) at frame 38:
    codes of 4 frames, the 10th holds it."""
    t = np.arange(80) / 20.0
    joints = np.zeros((80, 22, 3))
    joints[:, :, 2] = t[:, None]
    assert distance_cut(joints, 2.0, 20, 4) == 10
    assert distance_cut(joints, 3.9, 20, 4) == 20 and distance_cut(joints, 5.0, 20, 4) is None


def test_the_samples_that_reach_the_distance_are_chosen_among():
    """Of candidates walking 1.0, 1.5 and 2.0 m/s for 2 s (features: metres a frame at 20 fps),
    3 m asks the two that get there; 5 m, which none reaches, the longest; a candidate already set
    aside stays aside."""
    from shapemove.core.generation.stop_words import reaching

    def walk(speed):
        f = np.zeros((40, 263))
        f[:, 2] = speed / 20.0
        return f

    feats = [walk(1.0), walk(1.5), walk(2.0)]
    every = np.ones(3, bool)
    assert reaching(feats, 3.0, every).tolist() == [False, True, True]
    assert reaching(feats, 5.0, every).tolist() == [False, False, True]
    assert reaching(feats, 3.0, np.array([True, True, False])).tolist() == [False, True, False]
    assert reaching(feats, 5.0, np.array([True, False, False])).tolist() == [True, False, False]


@pytest.fixture(scope="module")
def gen_default():
    from shapemove.core.generation.generate import Generator

    return Generator(None)


@pytest.fixture
def codes_only(gen_default):
    """A timeline of codes (captured takes off, ``--no-library``): these tests read its codes; the
    timeline of finished segments is tests/test_stitched_timeline.py's."""
    gen_default.set_captured(False)
    yield
    gen_default.set_captured(True)


def test_three_steps_and_a_stop(gen_default):
    """The default model: "a man takes three steps forward and stops" (4 s) strikes three times, then
    stands still for the last 1.5 s; a plain walk walks to the end. A taller body stops too. Without
    the stop word ("a man takes three steps forward") it stops too: it walked on to the end before."""
    from shapemove.core.generation.generate import Request
    from shapemove.core.motion.contacts import runs

    def speeds(m):
        r = m.joints[:, 0, [0, 2]]
        return np.linalg.norm(np.diff(r, axis=0), axis=1) * m.fps

    m = gen_default.generate_batch([Request("a man takes three steps forward and stops", seconds=4, seed=0)])[0]
    plain = gen_default.generate_batch([Request("a man walks forward", seconds=4, seed=0)])[0]
    s, p = speeds(m), speeds(plain)
    assert m.num_frames == 80 and m.tokens is not None and m.tokens[-1] == gen_default.rest_code
    assert s[:30].mean() > 0.5 and s[-30:].mean() < 0.08 and p[-30:].mean() > 0.5
    strikes = sorted(a for k in (0, 1) for a, _ in runs(m.contacts[:, k].astype(bool)) if a > 0)
    assert 3 <= len(strikes) <= 4                                  # three steps (and the closing one)
    J, C = m.joints[:, [7, 8, 10, 11]][:, :, [0, 2]], m.contacts.astype(bool)
    assert np.linalg.norm(np.diff(J, axis=0), axis=2)[C[1:] & C[:-1]].mean() < 0.5e-3    # feet planted
    free = gen_default.generate_batch([Request("a man takes three steps forward and stops", seed=0)])[0]
    assert free.tokens[-8:].tolist() == [gen_default.rest_code] * 8 and free.tokens[-9] != gen_default.rest_code
    assert speeds(free)[-24:].mean() < 0.08                      # no length asked: 1.6 s of standing after the stop
    counted = gen_default.generate_batch([Request("a man takes three steps forward", seconds=4, seed=0)])[0]
    assert speeds(counted)[:30].mean() > 0.5 and speeds(counted)[-30:].mean() < 0.08
    taller = gen_default.redecode(m, np.full(10, 0.8, np.float32))
    assert speeds(taller)[-30:].mean() < 0.08 and taller.joints[:, 0, 1].mean() > m.joints[:, 0, 1].mean()


def test_a_gait_asked_to_stop_goes_a_while_first(gen_default):
    """No length asked, no steps or distance counted: the gait goes ``GOING_SECONDS`` before it
    stops, then stands ``STAND_SECONDS``. "he jogs to the corner and stops" went 0.5 m in the half
    of the model's length it kept, the start of a jog from standing."""
    from shapemove.core.generation.generate import Request
    from shapemove.core.generation.stop_words import GOING_SECONDS, STAND_SECONDS

    for text in ("he jogs to the corner and stops", "a man runs forward and stops"):
        m = gen_default.generate_batch([Request(text, seed=0)])[0]
        assert m.num_frames == round((GOING_SECONDS + STAND_SECONDS) * m.fps), (text, m.num_frames)
        r = m.joints[:, 0, [0, 2]]
        going = round(GOING_SECONDS * m.fps)
        assert np.linalg.norm(r[going] - r[0]) > 4.0, text                  # a jog, a run: metres, not a start
        assert np.linalg.norm(r[-1] - r[going + 12]) < 0.15, text            # then standing
        assert m.tokens[-8:].tolist() == [gen_default.rest_code] * 8


@pytest.mark.usefixtures("codes_only")
def test_a_timeline_segment_that_stands_still_stands(gen_default):
    """"walks forward" -> "stands still" -> "walks forward": the T5 has no standing caption and its
    middle segment walked on (seed 0: 1.1-1.3 m/s); it is now the model's standing code, so the body
    halts early in the segment, stands, and walks on after it. Regenerate Strip keeps it."""
    from shapemove.core.generation.sequence import boundary_report, generate_sequence, regenerate_segment
    from shapemove.core.plan.reader import asks_stand_still

    assert asks_stand_still("a person stands still") and asks_stand_still("she waits")
    assert not asks_stand_still("she stands up") and not asks_stand_still("a man walks and stops")
    segs = [("a person walks forward", 2.0), ("a person stands still", 2.0), ("a person walks forward", 2.0)]

    def middle(m):   # root speed over the middle segment's last 1.4 s
        r = m.joints[:, 0, [0, 2]]
        return float(np.linalg.norm(np.diff(r[52:80], axis=0), axis=1).mean() * m.fps)

    plain = generate_sequence(gen_default, segs, seed=0, by_parts=False)
    m = generate_sequence(gen_default, segs, seed=0)
    assert middle(plain) > 0.5 and middle(m) < 0.1
    assert m.tokens[10:20].tolist() == [gen_default.rest_code] * 10
    assert boundary_report(m)["jump_ratio"] <= 2.0
    again = regenerate_segment(gen_default, m, 1, seed=4)
    assert middle(again) < 0.1


def test_two_things_at_once_then_a_stop(gen_default):
    """"walks forward waving, then stops" is made by part (a walk's legs, a wave's arms) and both
    parts stop at the same code: it walked waving to the end when the stop was generated whole
    (no arms stream); now the hand is up while it walks, down once it stands. A new body keeps it."""
    from shapemove.core.generation.generate import Request

    def speeds(m):
        r = m.joints[:, 0, [0, 2]]
        return np.linalg.norm(np.diff(r, axis=0), axis=1) * m.fps

    m = gen_default.generate_batch([Request("a woman walks forward waving, then stops", seconds=4, seed=0)])[0]
    rest = gen_default.rest_code
    assert m.part_prompts is not None and m.arms_tokens is not None and m.prompt.endswith("then stops")
    assert m.tokens[-1] == rest and m.arms_tokens[-1] == rest and len(m.tokens) == len(m.arms_tokens)
    assert (m.tokens == rest).sum() == (m.arms_tokens == rest).sum() >= 5       # cut at the same code
    s = speeds(m)
    assert s[:30].mean() > 0.5 and s[-30:].mean() < 0.08
    hand_up = (m.joints[:, [20, 21], 1] - m.joints[:, [16, 17], 1]).max(1)     # wrist over shoulder, m
    assert hand_up[:40].max() > 0.1 and hand_up[-30:].max() < 0.0
    counted = gen_default.generate_batch([Request("a man takes three steps forward", seconds=4, seed=0)])[0]
    assert speeds(counted)[:30].mean() > 0.5 and speeds(counted)[-30:].mean() < 0.08
    taller = gen_default.redecode(m, np.full(10, 0.8, np.float32))
    assert speeds(taller)[-30:].mean() < 0.08 and taller.arms_tokens is not None


@pytest.mark.usefixtures("codes_only")
def test_a_timeline_segment_that_counts_its_steps_stands_after_them(gen_default):
    """"a man takes three steps forward" 3 s -> "he waves" 2 s: the first segment walks three steps
    (and the closing one) and stands until the wave; without the word edits it walked its 3 s
    (seed 0: 1.1 m/s at 2 s). Regenerate Strip keeps it."""
    from shapemove.core.generation.sequence import boundary_report, generate_sequence, regenerate_segment
    from shapemove.core.motion.contacts import runs

    segs = [("a man takes three steps forward", 3.0), ("he waves", 2.0)]

    def speed(m, a, b):
        r = m.joints[a:b + 1, 0, [0, 2]]
        return float(np.linalg.norm(np.diff(r, axis=0), axis=1).mean() * m.fps)

    plain = generate_sequence(gen_default, segs, seed=0, by_parts=False)
    m = generate_sequence(gen_default, segs, seed=0)
    assert speed(plain, 35, 50) > 0.5 and speed(m, 0, 20) > 0.5 and speed(m, 40, 60) < 0.1
    strikes = [a for k in (0, 1) for a, _ in runs(m.contacts[:60, k].astype(bool)) if a > 0]
    assert 3 <= len(strikes) <= 4 and m.tokens[14] == gen_default.rest_code
    assert boundary_report(m)["jump_ratio"] <= 2.0
    again = regenerate_segment(gen_default, m, 0, seed=3)   # a brisker walk: its three steps end by 2.5 s
    assert speed(again, 50, 60) < 0.1
    assert 3 <= len([a for k in (0, 1) for a, _ in runs(again.contacts[:60, k].astype(bool)) if a > 0]) <= 4


def test_a_walk_goes_the_distance_asked_and_stands(gen_default):
    """"a man walks 3 metres forward" (6 s) is cut where the body is 3 m from its start and stands
    there; one asked further than it can walk in the length says so. A timeline's segment too."""
    from shapemove.core.generation.generate import Request
    from shapemove.core.generation.sequence import generate_sequence

    def gone(m, a=0, b=None):
        r = m.joints[:, 0, [0, 2]]
        return float(np.linalg.norm(r[(len(r) if b is None else b) - 1] - r[a]))

    m = gen_default.generate_batch([Request("a man walks 3 metres forward", seconds=6, seed=0)])[0]
    assert abs(gone(m) - 3.0) < 0.3 and m.prompt == "a man walks 3 metres forward"
    speed = np.linalg.norm(np.diff(m.joints[-20:, 0, [0, 2]], axis=0), axis=1).mean() * m.fps
    assert speed < 0.1 and m.tokens is not None                       # stands for its last second, tokens kept
    far = gen_default.generate_batch([Request("a man walks 10 metres", seconds=4, seed=0)])[0]
    assert gone(far) < 8 and any("of the 10.0 m asked" in n for n in far.notes)
    t = generate_sequence(gen_default, [("a man walks 3 metres forward", 4.0), ("he waves", 2.0)], seed=0)
    (a, b), _ = t.segment_bounds
    assert abs(gone(t, a, b) - 3.0) < 0.3                                 # before: 2.0-2.1 m, cut at half


def test_a_timeline_distance_is_cut_on_its_own_body_and_a_wave_after_it_stands(gen_default):
    """"a man walks 3 metres forward" 4 s -> "he waves" 2 s on "a 6 ft 2, 200 lb man": the cut was
    read on the average body, so the tall man's longer strides walked 3.51 m, and his sampled wave
    shuffled 0.27 m on; the cut is read on the timeline's body (of the codes ``distance_keeps``
    tries, the one that stands nearest 3 m) and a segment of gestures only stands."""
    from shapemove.core.generation.sequence import generate_sequence
    from shapemove.core.generation.stop_words import distance_keeps, from_start
    from shapemove.core.plan.reader import gestures_only

    assert distance_keeps(5, 20) == [3, 4, 5, 6] and distance_keeps(1, 20) == [1, 2] and distance_keeps(20, 20) == [18, 19, 20]
    assert gestures_only("he waves") and gestures_only("a person raises the left hand")
    assert not gestures_only("she waves while walking") and not gestures_only("a person jumps")
    m = generate_sequence(gen_default, [("a man walks 3 metres forward", 4.0), ("he waves", 2.0)],
                          shape_text="a 6 ft 2, 200 lb man", seed=0)
    (a, b), (c, e) = m.segment_bounds
    assert abs(from_start(m.joints[a:b])[-1] - 3.0) <= 0.15                # within 5 %
    assert from_start(m.joints[c:e]).max() < 0.1                          # standing while it waves


def test_a_short_body_walks_the_distance_asked(gen_default):
    """A 5 ft 1 woman's "a man walks 3 metres forward" (seed 0) stopped 2.58 m out, and a 4 ft 6
    child's 4 s timeline segment 2.59 m: a slow sample was chosen, read on the T5's own body. The
    samples that get there on the body asked compete; a length no sample can do says so."""
    from shapemove.core.generation.generate import Request
    from shapemove.core.generation.sequence import generate_sequence
    from shapemove.core.generation.stop_words import from_start

    gen = gen_default
    m = gen.generate_batch([Request("a man walks 3 metres forward", shape_text="a 5 ft 1 woman", seed=0)])[0]
    assert abs(from_start(m.joints)[-1] - 3.0) <= 0.15
    t = generate_sequence(gen, [("a man walks 3 metres forward", 4.0), ("he waves", 2.0)], shape_text="a 4 ft 6 child", seed=0)
    (a, b), _ = t.segment_bounds
    assert abs(from_start(t.joints[a:b])[-1] - 3.0) <= 0.15
    short = gen.generate_batch([Request("a man walks 3 metres forward", shape_text="a 4 ft 6 child", seed=0, seconds=4.0)])[0]
    went = from_start(short.joints)[-1]
    assert went >= 2.88 or any("of the 3.0 m asked" in n for n in short.notes)


def test_a_prompt_that_stands_still_stands(gen_default):
    """"a person stands still" alone: no caption stands still (the nearest captured take walks
    backwards at 1.1 m/s), so it is the model's standing code for the length asked."""
    from shapemove.core.generation.generate import Request

    m = gen_default.generate_batch([Request("a person stands still", seconds=2.0, seed=1)])[0]
    r = m.joints[:, 0, [0, 2]]
    assert np.linalg.norm(np.diff(r, axis=0), axis=1).mean() * m.fps < 0.05
    assert m.tokens.tolist() == [gen_default.rest_code] * 10 and m.provenance == "generated"

