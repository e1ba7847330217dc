"""An action that is no gait asked slowly: its moving part played at SLOW_ACTION of its speed."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.slow_action import MIN_GAIN, SLOW_ACTION, STILL, moving_frames, slowed

pytestmark = pytest.mark.usefixtures("one_thread")


def test_the_still_end_is_what_no_joint_moves_in():
    j = np.zeros((30, 22, 3))
    j[:20, 0, 1] = np.linspace(0.9, 0.2, 20)      # frames 0-19 go down, 20-29 hold frame 19's pose
    j[20:] = j[19]
    assert moving_frames(j) == 20
    j[25, 5, 0] = STILL / 2                        # a tremor under STILL is still
    j[26:] = j[25]
    assert moving_frames(j) == 20
    assert moving_frames(np.zeros((10, 22, 3))) == 2


def test_a_sit_asked_slowly_takes_longer_to_reach_the_floor():
    """"an old man sits down" (4 s, seed 0) reaches the floor at frame f; slowly, at the model's
    length, the sit lasts 1 / SLOW_ACTION as long and the motion with it; at 4 s the sit takes up
    its held end, reaching the floor later and keeping the length."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.plan.words import read_words

    gen = Generator(None)
    m = gen.generate_batch([Request("an old man sits down", seconds=4, seed=0)])[0]
    down = lambda x: int(np.argmax(x.joints[:, 0, 1] < 0.35 * x.joints[0, 0, 1]))  # noqa: E731
    active = moving_frames(m.network_joints)
    asked = read_words("an old man sits down slowly")
    assert slowed(m, gen.body, read_words("an old man sits down"), False) is m   # not asked slowly
    long = slowed(m, gen.body, asked, keep_length=False)
    assert long.num_frames == m.num_frames - active + round(active / SLOW_ACTION)
    assert down(long) == pytest.approx(down(m) / SLOW_ACTION, abs=3)
    assert np.abs(long.joints[-1] - m.joints[-1]).max() < 0.03             # it ends as it did, seated
    kept = slowed(m, gen.body, asked, keep_length=True)
    assert kept.num_frames == m.num_frames and down(m) < down(kept) <= down(long) + 1
    assert "played slowly" in kept.notes[-1] and kept.provenance == m.provenance
    short = gen.generate_batch([Request("an old man sits down", seconds=1.5, seed=0)])[0]   # the sit fills 1.5 s
    assert moving_frames(short.network_joints) * MIN_GAIN > short.num_frames
    same = slowed(short, gen.body, asked, keep_length=True)
    assert same is short and same.notes[-1] == (f"not played slowly: the action fills the {short.num_frames / 20:.1f} s "
                                                "asked (a longer length leaves it room)")
    slow = gen.generate_batch([Request("an old man sits down slowly", seed=0)])[0]   # through the generator
    assert "played slowly" in " ".join(slow.notes)
    seated = gen.generate_batch([Request("a man sits down slowly while waving", seed=0)])[0]   # by part too
    assert seated.part_prompts and "played slowly" in " ".join(seated.notes)
