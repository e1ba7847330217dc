"""Walking a course the words name (core/generation/course_walk.py): a circle, a figure eight, back and
forth, a zigzag, walked by a straight track the named way; a motion that does not travel left alone."""
import numpy as np
import pytest

from shapemove.core.generation.course_shapes import (ASIDE, BACK_AND_FORTH, CIRCLE, CORNER, DIAGONAL, EIGHT, MAX_RADIUS,
                                                    MIN_RADIUS, SIDE_MAX, SIDE_MIN, SQUARE, U_RADIUS, ZIG, ZIG_ANGLE, ZIGZAG,
                                                    radius_for)
from shapemove.core.generation.course_walk import course_line, course_turn
from shapemove.core.generation.course_walk import on_course as _on_course
from shapemove.core.plan.reader import course_named, straight_gait, turns_right
from shapemove.core.plan.words import read_words


def on_course(track, text, course=None):
    """The track walked along the course the plan reads in ``text`` (``course``: read elsewhere)."""
    w = read_words(text)
    return _on_course(track, course or w.course, w.course_right)
from shapemove.core.generation.track import Track, headings, root_centre


@pytest.mark.parametrize("text, circle, right", [
    ("a person walks in a circle", True, False),
    ("someone jogs around in a circle clockwise", True, True),
    ("she walks round in a circle to the right", True, True),
    ("walks in circles counter-clockwise", True, False),
    ("a man walks forward and turns to the right", False, True),
    ("a person waves", False, False),
])
def test_the_words_name_the_circle_and_its_way(text, circle, right):
    assert (course_named(text) == CIRCLE) == circle and turns_right(text) == right


def test_radius_goes_round_once_within_bounds():
    assert radius_for(2 * np.pi * 2.0) == pytest.approx(2.0)
    assert radius_for(1.0) == MIN_RADIUS and radius_for(100.0) == MAX_RADIUS
    line = course_line(2 * np.pi * 2.0, CIRCLE, right=False)
    quarter = line.point([np.pi])[0]                       # a quarter of a 2 m circle
    assert quarter == pytest.approx([2.0, 2.0], abs=0.02)  # turning left: towards +X (the body's left)
    assert line.point([np.pi])[0][0] == pytest.approx(-course_line(2 * np.pi * 2.0, CIRCLE, right=True).point([np.pi])[0][0])


def _straight_walk(frames=80, speed=1.2, fps=20.0):
    """A stick figure striding along +Z: hips, knees and feet swinging, the rest carried."""
    t = np.arange(frames) / fps
    j = np.zeros((frames, 22, 3))
    rest = np.array([[0, .9, 0], [.1, .85, 0], [-.1, .85, 0], [0, 1.0, 0], [.1, .5, 0], [-.1, .5, 0], [0, 1.1, 0],
                     [.1, .1, 0], [-.1, .1, 0], [0, 1.3, 0], [.1, .05, .1], [-.1, .05, .1], [0, 1.5, 0],
                     [.08, 1.4, 0], [-.08, 1.4, 0], [0, 1.6, 0], [.2, 1.4, 0], [-.2, 1.4, 0], [.25, 1.15, 0],
                     [-.25, 1.15, 0], [.25, .9, 0], [-.25, .9, 0]])
    j[:] = rest
    swing = 0.25 * np.sin(2 * np.pi * 1.8 * t)
    for k, s in ((4, 1), (7, 1), (10, 1), (5, -1), (8, -1), (11, -1)):
        j[:, k, 2] += s * swing
    j[..., 2] += speed * t[:, None]
    return Track(j, np.zeros((frames, 4), np.uint8))


def test_a_straight_walk_goes_round_the_circle_and_keeps_its_steps():
    walk = _straight_walk()
    bent = on_course(walk, "a person walks in a circle")
    assert bent.joints.shape == walk.joints.shape
    turn = np.unwrap(headings(bent.joints))
    assert turn[-1] - turn[0] > 2.5                                # about 3.8 rad of 4.8 m on a 1 m circle
    c = root_centre(bent.joints)                                   # on the 1 m circle about (1, 0)
    assert np.abs(np.linalg.norm(c - [MIN_RADIUS, 0.0], axis=1) - MIN_RADIUS).max() < 0.1
    right = on_course(walk, "a person walks in a circle clockwise")
    assert np.unwrap(headings(right.joints))[-1] - np.unwrap(headings(right.joints))[0] < -2.5
    local = lambda J: np.linalg.norm(J[:, 10] - J[:, 11], axis=-1)  # noqa: E731  the feet's stride, kept
    assert np.allclose(local(bent.joints), local(walk.joints), atol=0.03)


def test_a_backward_walk_goes_round_backwards():
    """A stick figure stepping backwards (facing +Z, going -Z) bent round a circle keeps going the way
    its back faces (``polyline.gait_offset``: pi); a sidestep (going +X, the body's left) pi/2.
    Before, the body was turned to face the way the circle goes and its legs stepped backwards."""
    from shapemove.core.generation.polyline import gait_offset

    back = _straight_walk(speed=-1.2)
    assert abs(gait_offset(back.joints)) == pytest.approx(np.pi) and gait_offset(_straight_walk().joints) == 0.0
    side = _straight_walk(speed=0.0)
    side.joints[..., 0] += 1.2 * np.arange(80)[:, None] / 20.0
    assert gait_offset(side.joints) == pytest.approx(np.pi / 2)
    bent = on_course(back, "a person walks backwards in a circle")
    v = np.diff(root_centre(bent.joints), axis=0)
    h = headings(bent.joints)[1:]
    facing = np.stack([np.sin(h), np.cos(h)], axis=1)
    assert ((v * facing).sum(1) / np.linalg.norm(v, axis=1)).mean() < -0.9          # still backwards
    assert np.unwrap(headings(bent.joints))[-1] - np.unwrap(headings(bent.joints))[0] > 2.5   # and round


def test_a_motion_that_does_not_travel_is_left_alone():
    still = _straight_walk(speed=0.0)
    assert on_course(still, "a person walks in a circle") is still


def test_generation_walks_the_circle_the_prompt_asks_for():
    """The default model's "walks in a circle" goes round (the path judge of eval parts reads a
    circle), as an edit without tokens; with parts off it is the straight decoded walk."""
    from shapemove.core.eval.part_judge import path_of
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    m = gen.generate_batch([Request("a person walks in a circle", seconds=4, seed=0)])[0]
    assert path_of(m.joints) == "walk in a circle" and m.tokens is None and m.features is not None
    assert np.unwrap(headings(m.joints))[-1] - np.unwrap(headings(m.joints))[0] > 1.5
    gen.set_captured(False)   # the model's own decoded walk (no captured take)
    plain = gen.generate_batch([Request("a person walks in a circle", seconds=4, seed=0, by_parts=False)])[0]
    assert plain.tokens is not None and path_of(plain.joints) != "walk in a circle"
    assert m.joints[:, :, 1].min() > -0.05                           # feet still on the floor


@pytest.mark.parametrize("text, course, straight", [
    ("a person walks in a figure eight", EIGHT, ("a person walks", "walk")),
    ("someone jogs a figure-8 path clockwise, waving", EIGHT, ("someone jogs, waving", "jog")),
    ("a man runs in a circle to the right", CIRCLE, ("a man runs", "run")),
    ("walks in circles counter-clockwise", CIRCLE, ("walks", "walk")),
    ("a person goes around in a circle", CIRCLE, ("a person walks", "walk")),   # no gait left: a walk
    ("she circles the room", CIRCLE, ("she walks", "walk")),
    ("a man walks forward to the right", None, None),
    ("a man paces back and forth", BACK_AND_FORTH, ("a man walks", "walk")),
    ("a nervous woman is pacing up and down the hallway", BACK_AND_FORTH, ("a nervous woman is walking", "walk")),
    ("a guard jogs back and forth", BACK_AND_FORTH, ("a guard jogs", "jog")),
    ("a person rocks back and forth", None, None),                  # no gait: not a course
    ("a person steps back and forth", None, None),
    ("a soldier zigzags across the field", ZIGZAG, ("a soldier walks across the field", "walk")),
    ("someone runs in a zigzag", ZIGZAG, ("someone runs", "run")),
    ("a man walks at a steady pace", None, None),
    ("The hiker paces ahead at a steady clip.", None, None),
    ("Walk forward while rotating your arms in circles.", None, None),
    ("a person walks in circles, swinging the arms", CIRCLE, ("a person walks, swinging the arms", "walk")),          # "paces" sent on: a walk, no course
    ("a worried father paces the hospital corridor", BACK_AND_FORTH, ("a worried father walks the hospital corridor", "walk")),
    ("he is pacing nervously", BACK_AND_FORTH, ("he is walking nervously", "walk")),
    ("a woman walks diagonally to the right", DIAGONAL, ("a woman walks", "walk")),
    ("someone runs off at an angle", DIAGONAL, ("someone runs off", "run")),
    ("the dancer moves diagonally", None, None),                     # no gait
    ("a man runs to the left", ASIDE, ("a man runs", "run")),        # a gait to one side: turns that way
    ("she jogs off to her right", ASIDE, ("she jogs off", "jog")),
    ("he steps to the left", None, None),                            # a step aside is a sidestep
    ("a woman sidesteps to the right", None, None),
    ("a man turns to the left", None, None),                         # a turn, no gait
    ("a person walks in a square", SQUARE, ("a person walks", "walk")),
    ("a man jogs around a small square clockwise", SQUARE, ("a man jogs", "jog")),
    ("she goes around in a square", SQUARE, ("she walks", "walk")),  # no gait, a way gone: walked
    ("he walks across the town square", None, None),                 # a place, not a course
    ("a man walks around the square", None, None),
    ("a woman stands in a square", None, None),
])
def test_the_words_name_the_course_and_the_gait_walked_straight(text, course, straight):
    assert course_named(text) == course and straight_gait(text) == straight


def test_the_eight_is_two_loops_touching_at_the_start():
    """Hand-derived: loops of radius r = distance / 4 pi (here 1.5 m), the first to the left (+X),
    centred at (r, 0); half round it is (2r, 0), once round the start heading +Z again, then the
    other loop, centred at (-r, 0)."""
    r = 1.5
    line = course_line(4 * np.pi * r, EIGHT, right=False)
    quarter = np.pi * r / 2
    pts = line.point([np.pi * r, 2 * np.pi * r, 3 * np.pi * r, 4 * np.pi * r])
    assert pts == pytest.approx(np.array([[2 * r, 0], [0, 0], [-2 * r, 0], [0, 0]]), abs=0.02)
    assert line.point([quarter])[0] == pytest.approx([r - r * np.cos(np.pi / 2), r], abs=0.02)
    assert np.abs(np.linalg.norm(line.point(np.linspace(0.1, 2 * np.pi * r - 0.1, 50)) - [r, 0], axis=1) - r).max() < 0.02
    yaw = line.heading([np.pi * r, 3 * np.pi * r])
    assert yaw[0] == pytest.approx(np.pi, abs=0.05) and yaw[1] == pytest.approx(np.pi, abs=0.05)  # back the other way
    mirrored = course_line(4 * np.pi * r, EIGHT, right=True).point([np.pi * r, 3 * np.pi * r])
    assert mirrored == pytest.approx(np.array([[-2 * r, 0], [2 * r, 0]]), abs=0.02)
    assert radius_for(2.0) == MIN_RADIUS and course_line(2.0, EIGHT, False).length > 4 * np.pi * MIN_RADIUS   # once round at least


def test_back_and_forth_and_zigzag_lines():
    """Hand-derived: back and forth for 10 m is a leg of 5 - 0.3 pi m out along +Z, a U-turn of
    U_RADIUS to the left, the leg back 0.6 m aside, a U-turn; a zigzag goes ZIG m at 45 degrees to
    the left, then ZIG m at 45 degrees to the right."""
    leg = 5.0 - np.pi * U_RADIUS
    line = course_line(10.0, BACK_AND_FORTH, right=False)
    assert line.point([leg])[0] == pytest.approx([0.0, leg], abs=0.02)
    assert line.point([leg + np.pi * U_RADIUS])[0] == pytest.approx([2 * U_RADIUS, leg], abs=0.02)
    assert line.point([2 * leg + np.pi * U_RADIUS])[0] == pytest.approx([2 * U_RADIUS, 0.0], abs=0.02)
    assert line.point([10.0])[0] == pytest.approx([0.0, 0.0], abs=0.02)                # out and back, once
    assert line.heading([leg / 2, leg + np.pi * U_RADIUS + leg / 2]) == pytest.approx([0.0, np.pi], abs=0.02)
    zig = course_line(6.0, ZIGZAG, right=False)
    d = np.sin(ZIG_ANGLE) * ZIG
    assert zig.point([ZIG, 2 * ZIG, 4 * ZIG])[:, 1] == pytest.approx([d, 2 * d, 4 * d], rel=0.05)   # on along +Z (eased corners: a little more)
    assert zig.point([ZIG])[0][0] == pytest.approx(d, abs=0.1) and abs(zig.point([2 * ZIG])[0][0]) < 0.05
    assert zig.heading([ZIG / 2, 1.5 * ZIG]) == pytest.approx([ZIG_ANGLE, -ZIG_ANGLE], abs=0.02)


def test_the_square_goes_four_equal_sides_and_back_to_its_start():
    """Hand-derived: 12 m walked on a square is once round sides of 3 m (SIDE_MIN <= 12 / 4 <= SIDE_MAX),
    a quarter turn left at the end of each over CORNER m: the first side along +Z, the second
    towards +X (the body's left), back at the start heading +Z; to the right, the second side
    towards -X. A short walk still gets SIDE_MIN sides, a long one SIDE_MAX."""
    side = 3.0
    line = course_line(4 * side, SQUARE, right=False)
    mid = [side / 2, 1.5 * side, 2.5 * side, 3.5 * side]                     # the middle of each side
    assert line.heading(mid) == pytest.approx([0.0, np.pi / 2, np.pi, 1.5 * np.pi], abs=0.01)
    a = CORNER / (np.pi / 2)                  # a corner as a quarter circle of CORNER m: a 0.38 m radius
    second = line.point([1.5 * side])[0]      # straight on to the first corner, round it, half the second side
    assert second == pytest.approx([a + side / 2, side - CORNER + a], abs=0.05)
    assert line.point([4 * side])[0] == pytest.approx([0.0, 0.0], abs=0.05)  # once round, back where it began
    assert line.heading([4 * side - 0.01])[0] > 1.9 * np.pi                 # heading +Z again: the fourth corner
    right = course_line(4 * side, SQUARE, right=True)
    assert right.point([1.5 * side])[0][0] < -side / 2
    assert course_line(2.0, SQUARE, False).length >= 4 * SIDE_MIN - 0.01
    assert course_line(40.0, SQUARE, False).point([4 * SIDE_MAX])[0] == pytest.approx([0.0, 0.0], abs=0.05)


def test_the_diagonal_turns_to_45_degrees_and_keeps_it():
    """Hand-derived: after its first DIAGONAL_EASE (0.6) m the diagonal to the right heads -45
    degrees (towards -X, the body's right) and goes on straight that way."""
    line = course_line(5.0, DIAGONAL, right=True)
    assert line.heading([0.0])[0] == pytest.approx(0.0, abs=0.15)
    assert line.heading([1.0, 3.0, 5.0]) == pytest.approx([-np.pi / 4] * 3, abs=0.01)
    d = line.point([5.0])[0] - line.point([1.0])[0]
    assert d == pytest.approx(4.0 * np.array([-1.0, 1.0]) / np.sqrt(2), abs=0.01)
    assert course_turn(np.zeros(11), np.linspace(0, 5.0, 11), DIAGONAL, False)[-1] == pytest.approx(np.pi / 4)


def test_a_gait_to_one_side_turns_a_quarter_and_goes_on_that_way():
    """Hand-derived: "runs to the left" heads +90 degrees (+X, the body's left) once past its first
    ASIDE_EASE (1.2) m and goes straight on; to the right -90 degrees; "she jogs off to her right" is
    the right. In a timeline each segment turns a quarter from the way the last left it."""
    from shapemove.core.plan.words import read_words

    left, right = course_line(6.0, ASIDE, right=False), course_line(6.0, ASIDE, right=True)
    assert left.heading([0.0])[0] == pytest.approx(0.0, abs=0.1)
    assert left.heading([1.5, 4.0, 6.0]) == pytest.approx([np.pi / 2] * 3, abs=0.01)
    assert right.heading([1.5, 6.0]) == pytest.approx([-np.pi / 2] * 2, abs=0.01)
    d = left.point([6.0])[0] - left.point([2.0])[0]
    assert d == pytest.approx([4.0, 0.0], abs=0.01)
    assert course_turn(np.zeros(11), np.linspace(0, 5.0, 11), ASIDE, True)[-1] == pytest.approx(-np.pi / 2)
    assert read_words("she jogs off to her right").course_right and not read_words("a man runs to the left").course_right


def test_a_timeline_segment_turns_whole_periods_of_its_course():
    """``course_turn`` fits whole periods to the segment's travel: a circle's whole turn, an eight
    round and back, back and forth's two half turns; what the body turned by itself taken out."""
    s = np.linspace(0.0, 9.0, 91)
    still = np.zeros(91)
    assert course_turn(still, s, CIRCLE, False)[[0, 45, 90]] == pytest.approx([0, np.pi, 2 * np.pi])
    assert course_turn(still, s, EIGHT, False)[[0, 45, 90]] == pytest.approx([0, 2 * np.pi, 0], abs=1e-9)
    fro = course_turn(still, s, BACK_AND_FORTH, True)                     # right first: clockwise
    assert fro[[0, 30, 60, 90]] == pytest.approx([0, 0, -np.pi, -2 * np.pi], abs=1e-9)
    assert course_turn(np.linspace(0, 1, 91), s, CIRCLE, True)[-1] == pytest.approx(-2 * np.pi - 1)
    zig = course_turn(still, s, ZIGZAG, False)                            # 9 m: three periods of 3 m
    assert zig[[0, 7, 22, 30, 90]] == pytest.approx([0, ZIG_ANGLE, -ZIG_ANGLE, 0, 0], abs=1e-6)


def test_a_straight_walk_goes_round_the_eight():
    walk = _straight_walk(frames=200)                               # 12 m: once round two 0.95 -> 1 m loops
    bent = on_course(walk, "a person walks in a figure eight")
    turn = np.unwrap(headings(bent.joints))
    turn -= turn[0]
    assert turn.max() > 1.8 * np.pi and turn[-1] < turn.max() - 1.5 * np.pi    # round one way, then most of the way back
    c = root_centre(bent.joints)
    assert c[:, 0].max() > 1.8 and c[:, 0].min() < -1.8                       # both loops, either side of the start
    read = on_course(walk, "a person walks", EIGHT)                      # the caller read the eight elsewhere
    assert np.allclose(root_centre(read.joints), c)


def test_generation_walks_a_captured_eight_on_its_own_path():
    """"walks in a figure eight" plays one of CMU subject 105's captured eights on its own path (the
    codec loses turning; a walk bent onto the course is steered): round one loop, back round the
    other, the first loop to the left unless "clockwise" is said (its mirror image then); the feet
    on the floor. A jog on an eight is no take's gait: the jog is bent onto the course."""
    from shapemove.core.generation.course_takes import first_turn_right
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    for text, right in (("a person walks in a figure eight", False), ("a woman walks a figure-8 clockwise", True)):
        m = gen.generate_batch([Request(text, seconds=10, seed=0)])[0]
        assert m.provenance.startswith("captured: CMU cmu_105_") and m.num_frames == 200
        h = np.unwrap(headings(m.joints))
        assert np.ptp(h) > 1.2 * np.pi                                        # most of a loop in 10 s
        assert first_turn_right(m.joints[:, 0]) is right
        assert m.joints[:, :, 1].min() > -0.05
    j = gen.generate_batch([Request("he jogs in a figure eight", seconds=8, seed=0)])[0]
    c = root_centre(j.joints)
    assert "cmu_105_" not in j.provenance and c[:, 0].max() > 1.0 and c[:, 0].min() < -1.0   # both bent loops
    d = gen.generate_batch([Request("a woman walks diagonally to the right", seconds=4, seed=0)])[0]
    r = root_centre(d.joints)
    from shapemove.core.generation.track import travel
    assert -55 < np.degrees(np.arctan2(*(r[-1] - r[0]))) < -35 and travel(d.joints)[-1] > 3.0   # before: -3 degrees


def test_generation_walks_a_square_round_and_back_to_its_start():
    """"a person walks in a square" (no length asked: once round) turns four quarter turns the same
    way and ends where it began, its feet on the floor; clockwise, the other way."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    for text, sign in (("a person walks in a square", 1.0), ("a man walks in a square clockwise", -1.0)):
        m = gen.generate_batch([Request(text, seed=0)])[0]
        h = np.unwrap(headings(m.joints))
        r = root_centre(m.joints)
        assert sign * (h[-1] - h[0]) > 1.7 * np.pi and np.linalg.norm(r[-1] - r[0]) < 0.8
        assert np.abs(r - r[0]).max() > 1.2 and m.joints[:, :, 1].min() > -0.05


def test_first_turn_right_reads_the_way_a_path_first_turns():
    """Hand-derived: a circle of radius 1 m walked at 1 m/s, counter-clockwise seen from above
    (x = 1 - cos t, z = sin t: heading from +z toward +x, the body's left) turns left; its mirror
    image (x negated) right; a straight line, or a turn under 45 degrees, neither."""
    from shapemove.core.generation.course_takes import first_turn_right

    t = np.arange(200) / 20.0
    left = np.stack([1 - np.cos(t), np.zeros_like(t), np.sin(t)], 1)
    assert first_turn_right(left) is False
    assert first_turn_right(left * np.array([-1, 1, 1])) is True
    line = np.stack([np.zeros_like(t), np.zeros_like(t), t], 1)
    assert first_turn_right(line) is None
    assert first_turn_right(left[:12]) is None                     # 0.55 rad: under 45 degrees
    assert first_turn_right(np.zeros((50, 3))) is None            # standing: no heading


def test_a_course_asked_no_length_gets_the_time_to_go_once_round():
    """Once round at the gait's typical pace, over 0.9 of it: a circle walked 6.28 m at 1.194 m/s in
    5.8 s, jogged (1.564 m/s) in 4.5 s, a figure eight walked in 11.7 s; no round for a diagonal."""
    from shapemove.core.generation.course_shapes import UNASKED_LEAST, UNASKED_MOST, course_seconds

    assert course_seconds(CIRCLE, 1.194) == pytest.approx(2 * np.pi / (0.9 * 1.194))
    assert course_seconds(CIRCLE, 1.564) == pytest.approx(4.46, abs=0.01)
    assert course_seconds(EIGHT, 1.194) == pytest.approx(4 * np.pi / (0.9 * 1.194))
    assert course_seconds(CIRCLE, 2.87) == UNASKED_LEAST and course_seconds(EIGHT, 0.3) == UNASKED_MOST
    assert course_seconds(DIAGONAL, 1.2) is None


@pytest.mark.parametrize("text, turn", [
    ("a woman walks in a circle", 2 * np.pi),
    ("she jogs in a circle", 2 * np.pi),
    ("a man walks slowly in a circle", 2 * np.pi),    # its length for the slowed pace
])
def test_generation_goes_once_round_with_no_length_asked(text, turn):
    """No length asked: not the model's own (a retrieved 1.6 s clip goes a quarter round) but the
    course's time, all the way round, a captured gait made straight and bent onto it."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    m = gen.generate_batch([Request(text, seed=0)])[0]
    h = np.unwrap(headings(m.joints))
    assert h[-1] - h[0] > 0.9 * turn and m.num_frames >= 80
    assert m.provenance.startswith("captured: ") and m.remakeable


def test_generation_goes_round_the_whole_eight_with_no_length_asked():
    """No length asked: the captured eight plays whole (15-23 s), round both loops and back where it
    started."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    for seed in (0, 1):
        m = gen.generate_batch([Request("he walks in a figure eight", seed=seed)])[0]
        h = np.unwrap(headings(m.joints))
        r = m.joints[:, 0, [0, 2]]
        assert m.provenance.startswith("captured: CMU cmu_105_") and m.num_frames >= 300
        assert np.ptp(h) > 1.4 * np.pi and np.linalg.norm(r[-1] - r[0]) < 0.5
        assert np.abs(r - r[0]).max() > 4.0                                # the eight's length, about 4.4 m
        assert m.joints[:, :, 1].min() > -0.05


def test_a_course_too_short_to_go_round_is_noted():
    """Hand-derived: 4 m walked on a figure eight goes 4 / (4 pi x 1 m) = 32 % of it (loops of at
    least MIN_RADIUS); 2 pi m on a circle goes once round; a diagonal has no round."""
    from shapemove.core.generation.course_shapes import round_share
    from shapemove.core.generation.course_walk import course_note

    assert round_share(EIGHT, 4.0) == pytest.approx(4.0 / (4 * np.pi * MIN_RADIUS))
    assert round_share(CIRCLE, 2 * np.pi) == pytest.approx(1.0) and round_share(DIAGONAL, 4.0) is None
    walk = _straight_walk(frames=80)                                  # 4 s
    from shapemove.core.generation.track import travel

    d = travel(walk.joints)[-1]
    note = course_note(EIGHT, walk.joints, 20.0)
    share = d / (4 * np.pi * max(MIN_RADIUS, d / (4 * np.pi)))
    assert note == (f"4.0 s goes {share:.0%} of the way round the figure eight: once round takes about "
                    f"{4.0 / share:.0f} s at this pace (ask for that length to go round)")
    assert course_note(CIRCLE, _straight_walk(frames=200).joints, 20.0) is None   # 10 s: round
    assert course_note(DIAGONAL, walk.joints, 20.0) is None
