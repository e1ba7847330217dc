"""Steps read from features: a count of steps asks for candidates that strike that often, a gait
that goes somewhere for candidates that step (generation/gait_steps.py)."""
import numpy as np


def _ankles(left, right, frames=60):
    """(frames, 263) features whose ankles (joints 7, 8) are 8 cm up, 18 cm during the frame spans given."""
    f = np.zeros((frames, 263), np.float32)
    for joint, spans in ((7, left), (8, right)):
        h = np.full(frames, 0.08, np.float32)
        for a, b in spans:
            h[a:b] = 0.18
        f[:, 4 + (joint - 1) * 3 + 1] = h
    return f


def test_foot_strikes_count_the_feet_coming_down():
    from shapemove.core.generation.gait_steps import FIRST_STRIKE, foot_strikes, striking

    f = _ankles([(10, 20), (30, 40)], [(20, 30)])
    assert foot_strikes(f) == 3
    assert foot_strikes(_ankles([(0, FIRST_STRIKE - 1), (30, 40)], [(50, 60)])) == 1   # coming down at the start; still up at the end
    assert foot_strikes(_ankles([(10, 12)], [])) == 0                                # a twitch is no step
    slide = _ankles([], [])                                                           # "takes three steps backwards" slid 5.2 m
    keep = striking([slide, f, _ankles([(10, 20)], [])], 3, np.array([True, True, True]))
    assert keep.tolist() == [False, True, False]
    assert striking([slide, slide], 3, np.array([True, False])).tolist() == [True, False]   # none does: all stay


def test_a_gait_that_goes_somewhere_is_asked_of_candidates_that_step():
    from shapemove.core.generation.gait_steps import MIN_CADENCE, stepping
    from shapemove.core.plan.words import read_words

    walk = _ankles([(5, 15), (25, 35), (45, 55)], [(15, 25), (35, 45)], frames=80)   # 5 strikes in 4 s
    slide = _ankles([], [], frames=80)
    few = _ankles([(10, 20)], [(40, 50)], frames=80)                                   # 2 in 4 s: under 0.75 a second
    assert 2 < MIN_CADENCE * 4 <= 5
    everyone = np.ones(3, bool)
    assert stepping(read_words("a woman walks backwards and stops"), [slide, walk, few], everyone).tolist() == [False, True, False]
    for text in ("a man jogs in place", "a man waves", "a person stands still"):   # no gait going somewhere
        assert stepping(read_words(text), [slide, walk, few], everyone).all(), text
    assert stepping(read_words("a man walks"), [slide, few], np.ones(2, bool)).all()   # none steps: all compete
