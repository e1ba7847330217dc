"""Standing up from a seat is the sit before it played backwards (generation/reversed_rise.py)."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.reversed_rise import LEAD, ends_seated, sit_reversed
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
    same = sit_reversed(sit, 60, 1)
    assert np.array_equal(same.joints, sit.joints[::-1]) and same.provenance == "the sit of segment 1, played backwards"
    short = sit_reversed(sit, 30, 2)        # the seated stretch left out but LEAD frames: the rise kept
    assert len(short.joints) == 30 and short.joints[0, 0, 1] == pytest.approx(0.45)
    rise = int(np.argmax(short.joints[:, 0, 1] > 0.48))
    assert rise <= LEAD + 1 and short.joints[-1, 0, 1] > 0.85
    long = sit_reversed(sit, 90, 1)         # longer: standing held at the end
    assert len(long.joints) == 90 and np.allclose(long.joints[60:], sit.joints[0]) and long.contacts[60:].all()
    assert long.tokens is None and long.features is None and len(long.contacts) == 90


def test_sitting_down_then_standing_up_rises_from_the_seat(openbody):
    """"a man sits down, then stands up" (seed 0): the stand-up was DeepMimic's get-up from lying face
    down (the body went down on all fours first); now it rises from the pose the sit ends in and
    ends standing as the sit began."""
    from shapemove.core.generation.generate import Generator, Request

    m = Generator(None, body=openbody).generate_batch([Request("a man sits down, then stands up", seed=0)])[0]
    assert m.provenance.endswith("segment 2: the sit of segment 1, played backwards"), m.provenance
    (a, b), (c, d) = m.segment_bounds
    j = m.joints
    assert np.abs(j[c] - j[c - 1]).max() < 0.05                          # no jump at the seam
    assert j[c:c + 5, 0, 1].mean() < j[:5, 0, 1].mean() - 0.3            # seated when it starts
    assert j[-5:, 0, 1].mean() == pytest.approx(j[:5, 0, 1].mean(), abs=0.08)   # standing again
