"""Turning on the spot (core/generation/turn_words.py): the angle the words name, and the track
turned by it in all, its course turning with it."""
import numpy as np
import pytest

from shapemove.core.generation.track import Track, headings, root_centre
from shapemove.core.generation.turn_words import turned
from shapemove.core.plan.reader import angle_of

from test_course_walk import _straight_walk


@pytest.mark.parametrize("text, angle", [
    ("a person turns around", np.pi),
    ("someone turns around to the right", -np.pi),
    ("a man turns to the left", np.pi / 2),
    ("she turns right", -np.pi / 2),
    ("a person makes a quarter turn to the right", -np.pi / 2),
    ("someone spins around", 2 * np.pi),
    ("someone turns around twice", 2 * np.pi),
    ("a kid spins around three times", 6 * np.pi),     # a count of turns ("three times": one turn was made)
    ("a woman turns around 3 times", 3 * np.pi),
    ("a dancer spins 10 times", 10 * np.pi),           # at most MAX_TURNS turns of what is asked
    ("turn clockwise all the way around", -2 * np.pi),
    ("he turns his head", None),                       # a part turns, not the body
    ("back away slowly without turning around", None),  # negated
    ("waves, then turns around", None),                # another action too: the timeline's job
    ("walks forward and turns around", np.pi),         # a gait that turns: turned on its track
    ("she turns right and jogs on", -np.pi / 2),
    ("a man runs and spins", None),                    # a spin beside a gait is no turn of the track
    ("walks and jogs, then turns around", None),       # two gaits
    ("a person turns", None),                          # no amount named
    ("a person waves", None),
])
def test_the_words_name_the_angle(text, angle):
    got = angle_of(text)
    assert (got is None) if angle is None else got == pytest.approx(angle)


def test_a_walk_turned_around_walks_back_and_turns_in_all_what_was_asked():
    walk = _straight_walk(frames=100, speed=1.0)
    back = turned(walk, np.pi)
    h = np.unwrap(headings(back.joints))
    assert h[-1] - h[0] == pytest.approx(np.pi, abs=0.15)
    c = root_centre(back.joints)
    assert c[-1, 1] < c[60, 1] - 0.5          # after the turn it comes back along -Z
    assert 0.5 < abs(c[-1, 0]) < 2.5          # a U-turn on an arc of the steps taken while turning
    stride = lambda J: np.linalg.norm(J[:, 10] - J[:, 11], axis=-1)  # noqa: E731
    assert np.allclose(stride(back.joints), stride(walk.joints), atol=1e-6)   # the pose itself kept
    again = turned(back, np.pi)               # its own turn is counted: asked for pi, it stays pi
    h2 = np.unwrap(headings(again.joints))
    assert h2[-1] - h2[0] == pytest.approx(np.pi, abs=0.15)


def test_a_turn_on_the_spot_stays_on_the_spot():
    still = _straight_walk(speed=0.0)
    spun = turned(still, 2 * np.pi)
    h = np.unwrap(headings(spun.joints))
    assert h[-1] - h[0] == pytest.approx(2 * np.pi, abs=0.15)
    assert np.abs(root_centre(spun.joints) - root_centre(still.joints)).max() < 1e-6


def test_generation_turns_the_body_as_far_as_the_words_say():
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    m = gen.generate_batch([Request("a person turns around", seconds=4, seed=0)])[0]
    h = np.unwrap(headings(m.joints))
    assert h[-1] - h[0] == pytest.approx(np.pi, abs=0.4) and m.tokens is None and m.features is not None
    assert m.joints[:, :, 1].min() > -0.05
    gen.set_captured(False)   # the model's own motion, as it writes it (no captured take)
    plain = gen.generate_batch([Request("a person turns around", seconds=4, seed=0, by_parts=False)])[0]
    assert plain.tokens is not None


def test_a_turn_alone_is_turned_on_the_spot():
    """"a man turns right" (3 s) walked 2.8-3.1 m on the samples' walks: a turn or a spin alone, no
    way named, is read as on the spot, and turns there; beside a gait or a way it is not."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.plan.reader import travel_of

    assert travel_of("a man turns right").in_place and travel_of("a dancer spins").in_place
    assert not travel_of("a man turns right and walks away").in_place
    assert not travel_of("she turns left and goes forward").in_place and not travel_of("a man waves").in_place
    gen = Generator(None)
    for seed in (0, 1):
        m = gen.generate_batch([Request("a man turns right", seconds=3, seed=seed)])[0]
        h = np.unwrap(headings(m.joints))
        assert h[-1] - h[0] == pytest.approx(-np.pi / 2, abs=0.3)
        assert np.linalg.norm(m.joints[-1, 0, [0, 2]] - m.joints[0, 0, [0, 2]]) < 0.6


def test_a_gait_that_turns_turns_as_far_as_the_words_say():
    """"walks forward and turns around" and "turns around and walks away" read the turn beside the
    walk (it was read as an action and not acted on: the walks went on ahead); "jogs and turns
    left" a quarter turn. Each ends facing that far round (seeds 0-1, 4 s) and keeps going."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.track import travel

    gen = Generator(None)
    for text, angle in (("a man walks forward and turns around", np.pi),
                        ("a man turns around and walks away", np.pi), ("a woman jogs and turns left", np.pi / 2)):
        for seed in (0, 1):
            m = gen.generate_batch([Request(text, seconds=4, seed=seed)])[0]
            h = np.unwrap(headings(m.joints))
            assert h[-1] - h[0] == pytest.approx(angle, abs=0.4), (text, seed, h[-1] - h[0])
            assert travel(m.joints)[-1] > 1.5, (text, seed)


def test_a_return_after_a_segment_that_does_not_turn_turns_back():
    """"walks forward, then walks back" went on away from where it came ("back" unused, the samples
    walking backwards won the TMA); the plan gives the return half a turn, "back" is read as walking
    the way the body faces, and the second segment comes back (seed 0). After a turn, or alone, a
    return is read as it is."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.plan.plan import read_plan

    turns = lambda p: [s.words.turn for s in read_plan(p).segments]  # noqa: E731
    assert turns("a man walks forward, then walks back") == [None, pytest.approx(np.pi)]
    assert turns("a man walks forward, then turns around, then walks back") == [None, pytest.approx(np.pi), None]
    assert turns("a man walks to the door, then comes back and sits down") == [None, None]   # no gait returns
    assert turns("a man walks back") == [None]
    assert read_plan("a man walks forward, then walks back").segments[1].words.travel.forward == 1
    m = Generator(None).generate_batch([Request("a man walks forward, then walks back", seed=0)])[0]
    z = m.joints[:, 0, 2]
    (s1, e1) = m.segment_bounds[1]
    h = np.unwrap(headings(m.joints))
    assert h[e1 - 1] - h[s1] == pytest.approx(np.pi, abs=0.5)
    assert z[s1:].max() - z[-1] > 0.5                       # it comes back along -Z
