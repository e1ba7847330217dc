"""A captured take that holds still is offered only for a pose (generation/still_take.py)."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.still_take import STILL_SPEED, liveliest_speed, still_take

pytestmark = pytest.mark.usefixtures("one_thread")


def test_the_liveliest_joint_over_the_busiest_second():
    t = np.arange(60) / 20.0
    j = np.zeros((60, 22, 3))
    j[:, :, 1] = 1.0
    assert liveliest_speed(j) == 0.0 and liveliest_speed(j[:1]) == 0.0
    # a wrist on a 0.2 m circle at 2 rad/s: 0.4 m/s (chords of the sampled circle: 0.5 % less)
    j[:, 20, 0], j[:, 20, 1] = 0.2 * np.cos(2 * t), 1.0 + 0.2 * np.sin(2 * t)
    assert liveliest_speed(j) == pytest.approx(0.4, rel=0.01)
    # the whole body carried 1 m/s over the floor: the pelvis counts by its path, the others relative to it
    k = np.zeros((60, 22, 3))
    k[:, :, 2] = t[:, None]
    assert liveliest_speed(k) == pytest.approx(1.0)
    # a hand still for 2 s, then 0.6 m/s for 1 s: the busiest second, not the mean (0.2 m/s)
    h = np.zeros((60, 22, 3))
    h[40:, 21, 0] = 0.03 * np.arange(1, 21)
    assert liveliest_speed(h) == pytest.approx(0.6) and liveliest_speed(h, fps=10) == pytest.approx(0.3)


def test_a_static_pose_is_not_a_dance_but_a_sad_goodbye_waves(openbody):
    """The built-in library's CMU 49_15 ("static dance pose") is labelled dance: it holds still for
    "dance" and competes for a pose or standing still; the library's stillest other take (a sad
    wave goodbye) and a kick move."""
    from shapemove.core.generation.generate import Generator
    from shapemove.core.plan.words import read_words

    pool = Generator(None, body=openbody).pool
    statue = pool.window(pool.ids.index("cmu_49_15"), 80, 0)
    assert statue.action == "dance" and still_take(statue, "dance") and still_take(statue, None)
    assert not still_take(statue, "pose")
    assert not still_take(statue, None, read_words("a man waits"))
    for cid in ("dataset-1_bye_sad_001", "HDM_bd_kickLFront1Reps_003_120"):
        w = pool.window(pool.ids.index(cid), 80, 0)
        assert not still_take(w, w.action), cid


def test_dancing_in_place_is_not_a_statue(openbody):
    """"a woman dances in place" chose the static pose among its candidates on seeds 1, 4 and 5 (of
    0-5); now a motion that moves (its liveliest joint well above STILL_SPEED)."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.motion.features import motion_features, joints_from_features

    gen = Generator(None, body=openbody)
    for m in gen.generate_batch([Request("a woman dances in place", seed=s) for s in (1, 4, 5)]):
        assert "cmu_49_15" not in m.provenance
        assert liveliest_speed(joints_from_features(motion_features(m))) > 3 * STILL_SPEED, m.provenance
