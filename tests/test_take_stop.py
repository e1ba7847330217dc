"""A stop played on a captured take where the codes cannot carry the gait (generation/take_stop.py)."""
import numpy as np
import pytest

from shapemove.core.generation.take_stop import SETTLE, stop_frame


@pytest.fixture(scope="module")
def gen_default():
    from shapemove.core.generation.generate import Generator

    return Generator(None)


def test_the_stop_frame_of_a_take():
    contacts = np.zeros((60, 4), np.uint8)
    for a, b in ((0, 8), (20, 30), (40, 50)):      # joint 7 down at 0 (no step taken), 20 and 40
        contacts[a:b, 0] = 1
    contacts[30:40, 1] = 1                         # joint 8 down at 30
    root = np.zeros((60, 3), np.float32)
    root[:, 2] = -0.05 * np.arange(60)             # backwards, 5 cm a frame
    assert stop_frame(contacts, root, 1, None, 30) == 20 + SETTLE
    assert stop_frame(contacts, root, 3, None, 30) == 40 + SETTLE
    assert stop_frame(contacts, root, 4, None, 30) is None          # it strikes three times
    assert stop_frame(contacts, root, None, 1.0, 30) == 21          # 1 m from where it started
    assert stop_frame(contacts, root, None, 5.0, 30) is None        # 2.95 m at most
    assert stop_frame(contacts, root, None, None, 30) == 30 and stop_frame(contacts, root, None, None, 90) == 60


@pytest.mark.parametrize("text, seed", [("a man walks backwards 3 metres", 0), ("a woman walks backwards and stops", 0),
                                        ("a man takes two steps backwards", 1)])
def test_a_backward_walk_asked_to_stop_steps_and_stops(gen_default, text, seed):
    """The codec decodes a backward walk as a slide: "a woman walks backwards and stops" went 2.3 m with no
    ankle 4 cm off the floor, "a man walks backwards 3 metres" 2.7 m, "a man takes two steps backwards"
    slid 5.2 m. A captured backward walk is played instead, cut where the words stop it and held."""
    from shapemove.core.generation.gait_steps import foot_strikes
    from shapemove.core.generation.generate import Request
    from shapemove.core.generation.stop_words import from_start
    from shapemove.core.motion.features import motion_features

    m = gen_default.generate_batch([Request(text, seed=seed)])[0]
    assert m.provenance.startswith("captured:") and "walk-back" in m.provenance and "stopped at" in m.provenance
    f = motion_features(m)
    assert foot_strikes(f) >= 2 and (m.joints[:, 7, 1].max() - m.joints[:, 7, 1].min()) > 0.06   # it steps
    d = from_start(m.joints)
    fwd = m.joints[0, 1] - m.joints[0, 2]                              # left hip - right hip: the body's left
    facing = np.array([-fwd[2], fwd[0]]) / np.linalg.norm(fwd[[0, 2]])   # its forward (x, z)
    assert (m.joints[-1, 0, [0, 2]] - m.joints[0, 0, [0, 2]]) @ facing < -0.3   # backwards
    tail = m.joints[-16:, 0, [0, 2]]
    assert np.linalg.norm(tail - tail[0], axis=1).max() < 0.02           # standing at the end
    if "3 metres" in text:
        assert abs(d[-1] - 3.0) <= 0.15


def test_a_forward_walk_still_stops_in_its_codes(gen_default):
    from shapemove.core.generation.generate import Request

    m = gen_default.generate_batch([Request("a man takes three steps forward and stops", seed=0)])[0]
    assert m.tokens is not None and m.tokens[-1] == gen_default.rest_code and not m.provenance.startswith("captured")
