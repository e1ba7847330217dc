"""A captured take shorter than asked plays on as a loop where it repeats (generation/take_loop.py)."""
from __future__ import annotations

import numpy as np
import torch

from shapemove.core.generation.take_loop import looped_repetition, looped_take


def _take(openbody, arms, forward=0.05):
    """A standing body whose wrists and elbows follow ``arms`` (T,) metres up and down, walking
    ``forward`` m a frame; rotations carry their frame number, for the test to read the order."""
    rest = openbody.rest_joints(torch.zeros(1, 10))[0, :22].numpy().astype(np.float64)
    T = len(arms)
    J = np.repeat(rest[None], T, 0)
    J[:, 18:22, 1] += np.asarray(arms)[:, None]
    J[:, :, 2] += forward * np.arange(T)[:, None]
    rot = np.zeros((T, 24, 3, 3), np.float32)
    rot[:, 0, 0, 0] = np.arange(T)
    root = J[:, 0].astype(np.float32)
    return rot, root, np.zeros((T, 4), np.uint8), J


def test_a_repeating_take_loops_and_a_single_gesture_is_held(openbody):
    t = np.arange(90)
    still = np.zeros(15)
    arms = np.concatenate([still, 0.2 * np.sin(2 * np.pi * t / 20), still])   # 4.5 cycles of 1 s, standing around
    rot, root, con, J = _take(openbody, arms)
    out = looped_take(rot, root, con, J, 300)
    assert out is not None
    r, rt, c, first = out
    assert len(r) == len(rt) == len(c) == 300 and first <= len(rot)
    order = r[:, 0, 0, 0].astype(int)
    assert np.array_equal(order[:first], np.arange(first))               # the take as performed, then
    period = int(first - order[first])                                     # its cycle again and again
    assert period % 20 == 0 and 15 <= order[first] < first <= 15 + 90
    assert np.array_equal(order[first:first + period], np.arange(order[first], first))
    assert np.allclose(np.diff(rt[:, 2]), 0.05, atol=1e-4)                # the root walks on at its pace
    assert len(rot) > 0 and looped_take(rot, root, con, J, len(rot)) is None   # long enough: nothing to do

    kick = np.concatenate([np.zeros(30), 0.6 * np.sin(np.pi * np.arange(20) / 20), np.zeros(30)])
    assert looped_take(*_take(openbody, kick, 0.0), 300) is None          # one gesture: held, not repeated
    rise = np.linspace(0.0, 0.8, 80)
    assert looped_take(*_take(openbody, rise, 0.0), 300) is None          # never comes back: held


def test_one_repetition_of_a_repeated_action_plays_on(openbody):
    """One arm circle (arms up and back down once, standing before and after, swaying 1 mm a
    frame): not a repeat ``looped_take`` finds, but ``looped_repetition`` plays its busy stretch
    again, on the spot; a movement that ends elsewhere than it began is held."""
    circle = np.concatenate([np.zeros(10), 0.6 * np.sin(np.pi * np.arange(30) / 30), np.zeros(10)])
    rot, root, con, J = _take(openbody, circle, forward=0.001)
    assert looped_take(rot, root, con, J, 120) is None
    out = looped_repetition(rot, root, con, J, 120)
    assert out is not None
    r, rt, c, first = out
    assert len(r) == len(rt) == len(c) == 120
    order = r[:, 0, 0, 0].astype(int)
    a = int(order[first])
    assert np.array_equal(order[:first], np.arange(first)) and 8 <= a <= 11 and 39 <= first <= 42
    assert np.array_equal(order[first:first + (first - a)], np.arange(a, first))   # the circle again
    assert np.array_equal(rt[first], root[a])                                     # in place: no sway added up
    assert np.ptp(rt[:, 2]) < 0.06
    assert looped_repetition(rot, root, con, J, len(rot)) is None                 # long enough: nothing to do
    rise = np.concatenate([np.zeros(10), np.linspace(0.0, 0.8, 30), np.full(10, 0.8)])
    assert looped_repetition(*_take(openbody, rise, 0.0), 120) is None            # ends up high: held


def test_one_repetition_on_the_move_goes_on_at_its_pace(openbody):
    """One repetition that moves on at 1 m/s (a dribble while walking): played again, each repeat
    moved on by the repetition's travel, so the root keeps its pace across the seams."""
    stride = 0.15 * np.sin(2 * np.pi * np.arange(20) / 20)
    rot, root, con, J = _take(openbody, stride, forward=0.05)
    assert looped_take(rot, root, con, J, 100) is None             # one cycle: nothing repeats in it
    r, rt, c, first = looped_repetition(rot, root, con, J, 100)
    assert len(rt) == 100 and first == 20
    assert np.allclose(np.diff(rt[:, 2]), 0.05, atol=1e-4)         # 1 m/s all along, seams included
    # the same take for an action done on the spot (an arm circle whose performer stepped back): its
    # advance is never added, and without it the seam jumps back 0.95 m: held, not looped into a walk
    assert looped_repetition(rot, root, con, J, 100, travels=False) is None


def test_a_gait_loops_on_its_last_stride(openbody):
    """Four steps from standing, the contacts measured: the left foot down at frames 10 and 26 (a
    stride of 0.8 s), the right at 18 and 34; played on from the right foot's stride, the latest, to
    the frame its pose comes back, each repeat moved on by that stride's advance; the standing start
    left out (played from the first touch-down, frame 10, already at the stride's pace)."""
    from shapemove.core.generation.take_loop import last_stride, looped_gait

    T = 40
    t = np.arange(T)
    swing = np.where(t >= 10, 0.15 * np.sin(2 * np.pi * (t - 10) / 16), 0.0)     # arms swing with the steps
    rot, root, con, J = _take(openbody, swing, forward=0.0)
    pace = np.where(t >= 10, 0.07, 0.0)
    root[:, 2] = np.cumsum(pace)
    J[:, :, 2] += np.cumsum(pace)[:, None]
    for foot, downs in ((0, (10, 26)), (1, (18, 34))):
        for d in downs:
            con[d:d + 5, foot] = 1
    con[:5, :2] = 1                                                  # standing: both down, never touching down
    assert last_stride(con) == (18, 34)
    r, rt, c, first = looped_gait(rot, root, con, J, 100)
    order = r[:, 0, 0, 0].astype(int)
    assert len(r) == 100 and first == 24 and np.array_equal(order[:24], np.arange(10, 34))   # from the first step
    assert np.array_equal(order[24:40], np.arange(18, 34))          # the stride again
    assert np.allclose(np.diff(rt[:, 2]), 0.07, atol=1e-4)           # at its pace all along, the seams too
    assert np.array_equal(c[24:40], con[18:34])                      # its steps' contacts with it
    assert looped_gait(rot, root, con, J, T) is None                 # long enough: nothing to do
    still = np.zeros_like(con)
    still[:, :2] = 1
    assert last_stride(still) is None and looped_gait(rot, root, still, J, 100) is None   # no step: held


def test_two_steps_loop_as_a_step_and_its_mirror_image(openbody):
    """Two sneaking steps from standing: the left foot down at frame 8, the right at 20, neither
    twice, the left shoulder held turned (a sneak's arms are not symmetric). Played as performed to
    frame 20, then the step mirrored (the right foot leading, down at 20), then the step again (the
    left down at 32), the walker going on at its pace across every seam; the mirrored step starts
    from the pose before it, the shoulder's difference faded out over STEP_FADE frames."""
    from shapemove.core.generation.captured_takes import mirrored
    from shapemove.core.generation.take_loop import STEP_FADE, last_step, last_stride, looped_steps
    from shapemove.core.geometry.rotations import yaw_matrix

    T = 30
    t = np.arange(T)
    _, root, con, J = _take(openbody, np.zeros(T), forward=0.0)
    rot = np.repeat(np.eye(3, dtype=np.float32)[None, None], T, 0).repeat(24, 1)
    rot[:, 16] = yaw_matrix(0.5)                                       # the left shoulder turned
    pace = np.where(t >= 8, 0.05, 0.0)
    root[:, 2] = np.cumsum(pace)
    J[:, :, 2] += np.cumsum(pace)[:, None]
    con[8:13, 0] = 1                                                   # the left ankle down at 8
    con[20:25, 1] = 1                                                  # the right at 20
    con[:5, :2] = 1
    assert last_stride(con) is None and last_step(con) == (8, 20)
    r, rt, c, first = looped_steps(rot, root, con, J, 80, mirrored)
    assert len(r) == 80 and first == 20
    assert np.allclose(np.diff(rt[8:, 2]), 0.05, atol=1e-4)            # at its pace, the seams too
    assert np.allclose(rt[:, 0], root[0, 0], atol=1e-5)                # straight on
    assert c[20, 1] == 1 and c[20, 0] == 0 and c[32, 0] == 1           # right, then left again
    assert np.array_equal(c[20:32], con[8:20][:, [1, 0, 3, 2]])        # the step's contacts, mirrored
    assert np.allclose(r[20], r[19], atol=1e-5)                        # from the pose before it
    m_rot = mirrored(rot[8:20], root[8:20], con[8:20])[0]
    assert np.allclose(r[20 + STEP_FADE:32], m_rot[STEP_FADE:], atol=1e-5)   # then the mirror image itself
    assert np.allclose(r[20 + STEP_FADE, 17], yaw_matrix(-0.5), atol=1e-5)   # the right shoulder turned the other way
    assert looped_steps(rot, root, con, J, T, mirrored) is None        # long enough: nothing to do
    still = np.zeros_like(con)
    still[:, :2] = 1
    assert last_step(still) is None and looped_steps(rot, root, still, J, 80, mirrored) is None
