"""A contact run the decoded foot slides along (core/body/plant.py, foot_roll.py): planted piece by
piece, not at one point the foot leaps to. "a person does four squats" on "a 6 ft 2, 200 lb man"
(seed 0): the decoded body drifts 0.4 m backwards over a planted foot; its run's one point was up
to 0.5 m from the foot, and the right ankle leapt 0.72 m in a frame where the decoded ankle moves
at most 0.04 m."""
from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.usefixtures("one_thread")


def _slide(T=40, s=5, e=30, per_frame=0.03):
    """(T,22,3) joints with the left heel (7) sliding ``per_frame`` m a frame along -Z over frames
    s..e-1 (and on after it), a contact run there; the rest of the body still."""
    J = np.zeros((T, 22, 3))
    J[:, :, 1] = 0.9
    z = -per_frame * np.clip(np.arange(T) - s, 0, None)
    J[:, 7] = np.stack([np.full(T, 0.1), np.full(T, 0.08), z], axis=1)
    c = np.zeros((T, 4), np.uint8)
    c[s:e, 0] = 1
    c[:, 1] = 1   # the other heel planted throughout (the floor's reference)
    J[:, 8] = [-0.1, 0.08, 0.0]
    return J, c


def test_a_sliding_run_is_planted_piece_by_piece():
    from shapemove.core.body.plant import PIECE, anchor_track, bridged

    xz = np.stack([np.zeros(25), -0.03 * np.arange(25)], axis=1)        # 0.72 m along the run
    a = anchor_track(xz)
    assert np.abs(a - xz).max() <= PIECE + 0.03                          # never far from the foot
    assert np.linalg.norm(np.diff(a, axis=0), axis=1).max() <= 1.5 * 0.03
    still = np.stack([np.zeros(25), 0.004 * np.sin(np.arange(25))], axis=1)
    np.testing.assert_allclose(anchor_track(still), np.repeat(still.mean(0, keepdims=True), 25, axis=0))
    assert bridged([(0, 5), (7, 10), (14, 20)]) == [(0, 10), (14, 20)]


def test_plant_targets_follow_a_slide_without_a_leap():
    from shapemove.core.body.plant import plant_targets

    J, c = _slide()
    c[18:20, 0] = 0                                                     # the decoder's contact flickers off
    tgt, _ = plant_targets(J, c, np.array([0.08, 0.08, 0.02, 0.02]), fade_down=False)
    step = np.linalg.norm(np.diff(tgt[:, 7], axis=0), axis=1)
    assert step.max() <= 1.5 * 0.03, step.round(3)                      # one point per run: 0.3 m at its edge


def test_four_squats_on_a_tall_body_do_not_leap():
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.seam_pace import steps

    gen = Generator(None)
    m = gen.generate_batch([Request("a person does four squats", shape_text="a 6 ft 2, 200 lb man", seconds=12,
                                    seed=0)])[0]
    planted, decoded = steps(m.joints), steps(m.network_joints)
    assert planted.max() < 0.2, planted.max(0).round(2)                  # 0.72 m in a frame before (now 0.11)
    assert (planted.max(0) / np.maximum(decoded.max(0), 1e-6)).max() < 3.5  # 16.5 before (now 2.5)
    assert m.ik_error_cm < 5.0                                           # 7.4 cm before (now 3.8)


def test_planting_changes_are_eased_not_jumped():
    """A change that jumps (a foot planted 0.3 m from where the decoded one is) moves at most
    ``rate`` a frame, spread over both sides of the jump; ``lifted`` never goes below what it is
    given; ``fixed`` frames keep their change exactly."""
    from shapemove.core.body.plant import eased, lifted

    jump = np.r_[np.zeros(10), np.full(10, 0.3)][:, None]
    e = eased(jump, 0.05)
    assert np.abs(np.diff(e[:, 0])).max() <= 0.05 + 1e-12
    assert e[9, 0] > 0.0 and e[10, 0] < 0.3                         # eased before and after the jump
    assert e[0, 0] == 0.0 and e[-1, 0] == pytest.approx(0.3)
    keep = np.r_[np.zeros(10, bool), np.ones(10, bool)]
    f = eased(jump, 0.05, fixed=keep)
    assert np.allclose(f[10:, 0], 0.3) and np.abs(np.diff(f[:, 0])).max() <= 0.05 + 1e-12
    down = np.r_[np.zeros(5), np.full(5, -0.04), np.zeros(5)]       # a foot pulled 4 cm onto the floor
    v = lifted(down, 0.01)
    assert (v >= down - 1e-12).all() and np.abs(np.diff(v)).max() <= 0.01 + 1e-12
    assert (v[[4, 10]] == 0).all()                                  # the swing foot beside it is not lowered


def test_a_turned_foot_reads_its_own_pitch():
    """The pitch of a foot is measured in its own vertical plane: a flat foot turned a quarter
    about the vertical is still flat (read against the planted heading it was 60 degrees up)."""
    from shapemove.core.body.foot_roll import pitch_of

    e1 = np.array([0.0, 0.05, -1.0]) / np.linalg.norm([0.0, 0.05, -1.0])   # ball -> heel, a little up
    ball = np.zeros((2, 3))
    ankle = np.stack([0.15 * e1, 0.15 * np.array([e1[2], e1[1], 0.0])])   # as planted; turned a quarter
    np.testing.assert_allclose(pitch_of(ankle, ball, e1), [0.0, 0.0], atol=1e-9)
    up = 0.15 * np.array([0.0, np.sin(0.3 + np.arcsin(e1[1])), -np.cos(0.3 + np.arcsin(e1[1]))])
    assert pitch_of(up[None], ball[:1], e1)[0] == pytest.approx(0.3)


def test_a_foot_gliding_at_walking_pace_is_not_pinned():
    """A decoder's contact channel on while its heel glides 0.8 m/s ("a man walks backwards in a
    circle", seed 0: 0.7 m/s in its contact runs): not pinned (pinned, the knee leapt 2.5x its
    decoded step where the pin let go). A heel at rest, then slowing from rest to 0.5 m/s (under the
    detector's 0.7 m/s to stay), stays in contact."""
    from shapemove.core.body.plant import gate_contacts
    from shapemove.core.constants import FPS

    J, c = _slide(T=40, s=5, e=30, per_frame=0.8 / FPS)
    c[:, 0] = 1
    g = gate_contacts(J, c, np.zeros(4))
    assert g[:4, 0].all()          # still before the glide
    assert not g[7:30, 0].any()    # gliding: released
    assert g[:, 1].all()           # the still heel is untouched
    J2, c2 = _slide(T=40, s=20, e=40, per_frame=0.5 / FPS)
    c2[:, 0] = 1
    assert gate_contacts(J2, c2, np.zeros(4))[:, 0].all()   # entered at rest, held under the stay speed


def test_a_piecewise_plant_never_outruns_the_joint():
    """A heel the decoder slides along its run at a changing pace ("a person does five squats
    slowly": 0.3 m/s during a squat) is planted piece by piece, and the plant moves no faster in a
    frame than the joint itself does anywhere in the run (the pieces' 4-frame steps moved it 0.035 m
    in a frame against the decoded 0.021)."""
    from shapemove.core.body.plant import anchor_track

    pace = 0.008 + 0.004 * np.sin(np.linspace(0, np.pi, 40)) ** 2      # m a frame, 0.008 to 0.012
    xz = np.stack([np.zeros(40), -np.cumsum(pace)], axis=1)
    a = anchor_track(xz)
    assert np.linalg.norm(np.diff(a, axis=0), axis=1).max() <= pace.max() + 1e-9
    assert np.abs(a - xz).max() < 0.1                                   # and stays near the foot
