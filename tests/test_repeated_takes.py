"""A captured take of a counted action played for its repetitions (core/generation/repeated_takes.py):
"does three jumping jacks" plays three jacks of a capture, not the capture's side twists after them."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.repeated_takes import bouts, repeated_stretch
from shapemove.core.motion.contacts import runs


def _take(n: int, dips: list[tuple[int, int]]):
    """A take of ``n`` frames whose rotations and root carry their frame index, and a ``posed``
    whose features dip the root 0.5 m during ``dips``."""
    rot = np.arange(n, dtype=np.float32)[:, None, None, None] * np.ones((1, 24, 3, 3), np.float32)
    root = np.arange(n, dtype=np.float32)[:, None] * np.ones((1, 3), np.float32)
    con = np.ones((n, 4), np.uint8)

    def posed(r, rt, c):
        f = np.zeros((len(r) - 1, 263))
        f[:, 3] = 0.9
        for a, b in dips:   # the frames these rows were cut from keep their dips
            f[(rt[:-1, 0] >= a) & (rt[:-1, 0] < b), 3] = 0.4
        return None, f

    return rot, root, con, posed


def test_repetitions_fall_into_bouts():
    assert bouts([(0, 5), (20, 25), (40, 45), (120, 125)], 40) == [[(0, 5), (20, 25), (40, 45)], [(120, 125)]]
    assert bouts([], 40) == []


def test_the_longest_bout_plays_with_half_a_gap_either_side():
    # a bout of three squats (period 20 frames), a lone squat far after it, 200 frames in all
    rot, root, con, posed = _take(200, [(30, 36), (50, 56), (70, 76), (160, 166)])
    r, rt, c, exact = repeated_stretch(rot, root, con, posed, "squat", None, seed=0)
    assert not exact
    assert rt[0, 0] == 30 - 7 and rt[-1, 0] == 76 + 7 - 1   # half of the 14-frame gap each side
    assert len(r) == len(rt) == len(c) == 60


@pytest.mark.parametrize("seed", range(4))
def test_a_number_asked_cuts_that_many_in_a_row_halfway_between_repetitions(seed):
    rot, root, con, posed = _take(200, [(30, 36), (50, 56), (70, 76), (90, 96)])
    r, rt, c, exact = repeated_stretch(rot, root, con, posed, "squat", 2, seed=seed)
    assert exact
    frames = rt[:, 0]
    held = [(a, b) for a, b in [(30, 36), (50, 56), (70, 76), (90, 96)] if frames[0] <= a and b <= frames[-1] + 1]
    assert len(held) == 2 and held[1][0] - held[0][0] == 20          # two squats in a row, whole
    assert frames[0] in (23, 43, 63) and frames[-1] + 1 in (63, 83, 103)   # cut halfway, or half a gap out


def test_a_take_without_the_repetition_plays_as_it_is():
    rot, root, con, posed = _take(50, [])
    r, rt, c, exact = repeated_stretch(rot, root, con, posed, "squat", 3, seed=0)
    assert r is rot and not exact


def test_a_repetition_the_take_cuts_short_is_not_counted():
    rot, root, con, posed = _take(60, [(10, 16), (30, 36), (55, 60)])   # the third is cut by the take's end
    r, rt, c, exact = repeated_stretch(rot, root, con, posed, "squat", None, seed=0)
    assert rt[-1, 0] + 1 == 36 + 7   # the two whole squats and half their gap after the last


def _hands_up(joints) -> np.ndarray:
    return np.minimum(joints[:, 20, 1], joints[:, 21, 1]) > joints[:, 15, 1]


def _squatting(joints) -> np.ndarray:
    y = joints[:, 0, 1]
    return y < np.percentile(y, 90) - 0.2


def _raises(joints) -> int:
    """Both wrists above the head for 3+ frames, counted on the played joints."""
    return sum(1 for a, b in runs(_hands_up(joints)) if b - a >= 3)


def _squats(joints) -> int:
    """The pelvis 20 cm under its standing height for 3+ frames."""
    return sum(1 for a, b in runs(_squatting(joints)) if b - a >= 3)


def _kicking(joints) -> np.ndarray:
    """One ankle half a metre over the other (a kick's), counted on the played joints."""
    return np.abs(joints[:, 7, 1] - joints[:, 8, 1]) > 0.5


def _kicks(joints) -> int:
    return sum(1 for a, b in runs(_kicking(joints)) if b - a >= 3)


def test_the_default_model_plays_captured_jumping_jacks_and_squats_as_many_times_as_asked():
    """The built-in library's jumping jacks (CMU 14: three jacks, then jogging, squats, side twists)
    and single HDM05 squats, counted on the played joints: "three jumping jacks" three jacks,
    "five squats" five, each held after its last repetition, not inside one; plain "jumping jacks" plays jacks only (before: the
    take's first 10 s, three jacks and then its other actions; a counted prompt got a decoded
    sample whose jacks the codec had flattened: one raise of the hands)."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    for prompt, count, inside, want in [("a woman does three jumping jacks", _raises, _hands_up, 3),
                                        ("a man does five squats", _squats, _squatting, 5),
                                        ("someone squats twice", _squats, _squatting, 2),
                                        ("a man does three kicks", _kicks, _kicking, 3)]:
        for seed in (0, 1):
            m = gen.generate_batch([Request(prompt, seed=seed)])[0]
            assert m.provenance.startswith("captured:"), (prompt, m.provenance)
            assert count(m.joints) == want, (prompt, seed, count(m.joints))
            assert not inside(m.joints)[-1], (prompt, seed)   # held between repetitions, not in one
    plain = gen.generate_batch([Request("a woman does jumping jacks", seed=0, seconds=8)])[0]
    assert plain.provenance.startswith("captured:")
    assert _raises(plain.joints) >= 6   # a jack about every 1.1 s: the take's jacks played on, nothing else


def _flights(joints) -> int:   # both feet off the floor by 8 cm: one count per flight
    feet = joints[:, [7, 8, 10, 11], 1].min(1)
    return len(runs(feet - feet.min() > 0.08))


def test_again_and_again_plays_a_single_repetition_on_for_the_whole_length():
    """"A boy jumps up and down" (6 s) jumped once and stood 3.6 s (CMU's single jumps, held);
    said again and again (``Words.again``) the take's jump plays on, in place, as "she squats
    repeatedly" squats on; a number asked still counts ("jumps twice")."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.plan.words import read_words

    assert read_words("a boy jumps up and down").again and read_words("she squats repeatedly").again
    assert read_words("a kid keeps jumping").again and read_words("someone kicks over and over").again
    rope = read_words("a girl jumps rope")                                    # "rope" was said unused
    assert rope.again and rope.travel.in_place and rope.unused == ()
    assert not read_words("a man jumps twice").again and not read_words("a man walks up and down the hall").again
    assert not read_words("a man waves repeatedly").again                     # no counted action: said unused
    assert read_words("a man waves repeatedly").unused == ("repeatedly",)
    gen = Generator(None)
    jumps = gen.generate_batch([Request("a boy jumps up and down", seed=0, seconds=6)])[0]
    assert _flights(jumps.joints) >= 3, _flights(jumps.joints)
    assert np.linalg.norm(jumps.joints[-1, 0, [0, 2]] - jumps.joints[0, 0, [0, 2]]) < 0.3   # in place
    rope = gen.generate_batch([Request("a girl jumps rope", seed=0, seconds=6)])[0]   # a far jump, then standing
    assert _flights(rope.joints) >= 3 and np.linalg.norm(rope.joints[-1, 0, [0, 2]] - rope.joints[0, 0, [0, 2]]) < 0.3
    squats = gen.generate_batch([Request("she squats repeatedly", seed=0, seconds=6)])[0]
    assert _squats(squats.joints) >= 3, _squats(squats.joints)
    twice = gen.generate_batch([Request("a man jumps twice", seed=0, seconds=6)])[0]
    assert _flights(twice.joints) == 2, _flights(twice.joints)


def test_every_repetition_asked_plays_when_the_length_is_the_models():
    """"12 squats" need about 14-19 s of captured squats: with no length asked all twelve play (the
    model's own length stops at 10 s, which held 10); a length asked that holds fewer says so."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    m = gen.generate_batch([Request("a man does 12 squats", seed=0)])[0]
    assert m.provenance.startswith("captured:") and _squats(m.joints) == 12 and len(m.joints) > 200
    short = gen.generate_batch([Request("a man does 12 squats", seed=0, seconds=6)])[0]
    assert len(short.joints) == 120 and _squats(short.joints) < 12
    assert any("the repetitions asked take" in n and "hold fewer" in n for n in short.notes)


def test_a_kick_is_cut_to_its_repetitions_only_when_a_number_is_asked():
    from shapemove.core.generation.repeated_takes import cut_for

    assert cut_for("kick", 2) and not cut_for("kick", None)          # "a man kicks": the take's busiest window
    assert cut_for("squat", None) and cut_for("jumping jacks", 3)     # done over and over: its bout
    assert not cut_for("walk", 2) and not cut_for("punch", 3)         # not counted


def _kicks(joints) -> int:
    """Runs of frames with an ankle over 0.45 m above the other: one per kick."""
    lift = np.abs(joints[:, 7, 1] - joints[:, 8, 1])
    return len(runs(lift > 0.45))


def test_a_length_asked_keeps_a_punch_or_a_kick_going_on_the_spot():
    """"She kicks for eight seconds" kicked once and stood 6.7 s; an action a length keeps going
    (``vocabulary.KEPT_UP``) plays on as its repetitions, on the spot (a punch's take that steps
    forward went 10.5 m in 10 s of shadowboxing); a squat asked a length is held, not repeated."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.plan.words import read_words

    assert read_words("a man shadowboxes for ten seconds").again and read_words("she kicks for 8 seconds").again
    assert not read_words("a woman squats for 5 seconds").again and not read_words("he kicks twice for 8 seconds").again
    assert not read_words("she walks for ten seconds").again
    gen = Generator(None)
    kicks = gen.generate_batch([Request("she kicks for eight seconds", seed=0)])[0]
    assert kicks.num_frames == 160 and _kicks(kicks.joints) >= 3, _kicks(kicks.joints)
    assert np.linalg.norm(kicks.joints[-1, 0, [0, 2]] - kicks.joints[0, 0, [0, 2]]) < 0.5
    once = gen.generate_batch([Request("she kicks", seed=0, seconds=8)])[0]   # no length in the words: as before
    assert _kicks(once.joints) < _kicks(kicks.joints)
