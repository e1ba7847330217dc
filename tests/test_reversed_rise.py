"""Standing up from a seat is the sit before it played backwards (generation/reversed_rise.py)."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.reversed_rise import LEAD, ends_seated, held_low, sit_reversed
from shapemove.core.scene.motion_file import Motion

pytestmark = pytest.mark.usefixtures("one_thread")


def _body(root_y, head_y) -> np.ndarray:
    """(T,22,3) joints: every joint at the root's height but the head."""
    j = np.zeros((len(root_y), 22, 3))
    j[:, :, 1] = np.asarray(root_y)[:, None]
    j[:, 15, 1] = head_y
    return j


def test_a_seat_is_low_with_the_head_up():
    down = np.r_[np.full(10, 0.9), np.linspace(0.9, 0.45, 20), np.full(30, 0.45)]
    assert ends_seated(_body(down, down + 0.6))                        # a chair: head at 1.05 of 1.5
    assert not ends_seated(_body(down, np.r_[np.full(30, 1.5), np.full(30, 0.2)]))   # lying: the head on the floor
    assert not ends_seated(_body(np.full(60, 0.9), 1.5))               # standing all along
    assert not ends_seated(_body(down[:8], 1.5))                       # too short to tell


def test_the_sit_played_backwards_starts_seated_and_ends_standing():
    root = np.r_[np.full(10, 0.9), np.linspace(0.9, 0.45, 20), np.full(30, 0.45)]   # 60 frames, seated from 30
    sit = Motion(_body(root, root + 0.6), np.zeros(10), np.zeros((60, 24, 3)), np.zeros((60, 3)), 20.0, "openbody",
                 contacts=np.ones((60, 4), np.uint8), provenance="generated")
    for frames in (60, 30, 90):
        up = sit_reversed(sit, sit.contacts, frames, 1)
        y = up.joints[:, 0, 1]
        assert len(up.joints) == len(up.contacts) == frames and up.provenance == "segment 1 played backwards"
        # from LEAD frames before the root is 3 cm up (sit frame 27), the sit's way down backwards, then standing
        assert y[0] == pytest.approx(0.45) and int(np.argmax(y > 0.48)) == LEAD
        assert np.array_equal(up.joints[LEAD:LEAD + 18], sit.joints[27:9:-1])
        assert np.allclose(up.joints[LEAD + 18:], sit.joints[0]) and up.contacts[LEAD + 18:].all()
        assert up.tokens is None and up.features is None


def test_a_squat_before_a_stand_up_is_held_at_its_lowest():
    root = np.r_[np.full(5, 0.9), np.linspace(0.9, 0.4, 10), np.linspace(0.4, 0.9, 10), np.full(15, 0.9)]
    squat = Motion(_body(root, root + 0.6), np.zeros(10), np.zeros((40, 24, 3)), np.zeros((40, 3)), 20.0, "openbody",
                   contacts=np.ones((40, 4), np.uint8), notes=["the captured take lasts 1.2 s: its last pose is held "
                                                               "for the remaining 0.8 s"])
    low = held_low(squat, squat.contacts)
    assert len(low.joints) == 40 and np.allclose(low.joints[14:, 0, 1], 0.4) and np.array_equal(low.joints[:15], squat.joints[:15])
    assert low.notes == ["held at its lowest from 0.7 s: the next segment stands up"] and ends_seated(low.joints)
    assert held_low(low, low.contacts) is low                                  # lowest at its end already


def test_sitting_down_then_standing_up_rises_from_the_seat(openbody):
    """"a man sits down, then stands up" (seed 0): the stand-up was DeepMimic's get-up from lying face
    down (the body went down on all fours first); now it rises from the pose the sit ends in and
    ends standing as the sit began."""
    from shapemove.core.generation.generate import Generator, Request

    m = Generator(None, body=openbody).generate_batch([Request("a man sits down, then stands up", seed=0)])[0]
    assert m.provenance.endswith("segment 2: segment 1 played backwards"), m.provenance
    (a, b), (c, d) = m.segment_bounds
    j = m.joints
    assert np.abs(j[c] - j[c - 1]).max() < 0.05                          # no jump at the seam
    assert j[c:c + 5, 0, 1].mean() < j[:5, 0, 1].mean() - 0.3            # seated when it starts
    assert j[-5:, 0, 1].mean() == pytest.approx(j[:5, 0, 1].mean(), abs=0.08)   # standing again


def test_a_held_squat_then_standing_up_rises_from_the_crouch(openbody):
    """"a person does a squat, holds it, then stands up" (seed 5): the captured squat went down and
    up again and the stand-up was a get-up from lying face down; now the squat is held at its
    lowest to its segment's end and the stand-up rises from there."""
    from shapemove.core.generation.generate import Generator, Request

    m = Generator(None, body=openbody).generate_batch([Request("a person does a squat, holds it, then stands up", seed=5)])[0]
    assert m.provenance.endswith("segment 2: segment 1 played backwards"), m.provenance
    (a, b), (c, d) = m.segment_bounds
    y = m.joints[:, 0, 1]
    assert y[b - 10:b].max() < 0.6 * y[:5].mean()                        # still down at the end of the squat
    assert y[-5:].mean() == pytest.approx(y[:5].mean(), abs=0.05)         # up again


def test_regenerating_keeps_the_stand_up_on_its_seat(openbody):
    """Regenerate on a timeline's stand-up made it anew as a single prompt: a get-up from lying (the
    body went down on the floor to rise). Made again, it is the sit before it played backwards
    again; and the sit made again (another seed) has the stand-up rise from the new seat."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.sequence import regenerate_segment

    gen = Generator(None, body=openbody)
    m = gen.generate_batch([Request("a man sits down, then stands up", seed=0)])[0]
    up = regenerate_segment(gen, m, 1, seed=7)
    assert up.provenance.endswith("segment 2: segment 1 played backwards"), up.provenance
    (_, b), (c, _) = up.segment_bounds
    y = up.joints[:, 0, 1]
    assert y[c:].min() > y[b - 5:b].min() - 0.05                         # never lower than the seat: no floor
    assert y[-5:].mean() == pytest.approx(y[:5].mean(), abs=0.08)

    sat = regenerate_segment(gen, m, 0, seed=3)                          # the sit again: a new seat
    assert sat.provenance.endswith("segment 2: segment 1 played backwards"), sat.provenance
    (_, b), (c, _) = sat.segment_bounds
    j = sat.joints
    assert np.abs(j[c] - j[c - 1]).max() < 0.05                          # the rise starts where the new sit ends
    assert j[c:c + 5, 0, 1].mean() < j[:5, 0, 1].mean() - 0.3
