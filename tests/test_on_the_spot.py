"""A gait the words keep in place steps on the spot (core/generation/on_the_spot.py)."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.plan.reader import asks_on_the_spot
from shapemove.core.generation.stride_scale import scaled_strides

pytestmark = pytest.mark.usefixtures("one_thread")


def _walker(T: int = 60, v: float = 0.05) -> np.ndarray:
    """A body going +Z at ``v`` m/frame past a left ankle planted at z = 0.3 (x = 0.1), the right
    ankle swinging ahead and behind the pelvis, knees bent forward."""
    J = np.zeros((T, 22, 3))
    t = np.arange(T, dtype=np.float64)
    root = np.stack([0.02 * np.sin(t / 5), np.full(T, 0.9), v * t], 1)       # a little sideways sway
    J[:] = root[:, None]
    J[:, 1] += [0.1, -0.05, 0.0]            # hips: left at +x when facing +z
    J[:, 2] += [-0.1, -0.05, 0.0]
    J[:, 16] += [0.2, 0.5, 0.0]             # shoulders
    J[:, 17] += [-0.2, 0.5, 0.0]
    J[:, 7] = [0.1, 0.1, 0.3]               # left ankle: planted in the world
    J[:, 8] = root + np.stack([np.full(T, -0.1), 0.1 + 0.1 * np.abs(np.sin(t / 4)) - 0.9, 0.3 * np.sin(t / 4)], 1)
    for hip, knee, ankle, foot in ((1, 4, 7, 10), (2, 5, 8, 11)):
        J[:, knee] = (J[:, hip] + J[:, ankle]) / 2 + [0.0, 0.0, 0.08]
        J[:, foot] = J[:, ankle] + [0.0, -0.05, 0.12]
    return J


def test_the_words_that_keep_a_gait_in_place():
    assert asks_on_the_spot("a person jogs in place") and asks_on_the_spot("someone runs on the spot")
    assert asks_on_the_spot("a soldier marches in place, swinging his arms")
    assert not asks_on_the_spot("a person jogs forward")            # travel asked for
    assert not asks_on_the_spot("someone waves in place")           # no gait: nothing to keep from travelling
    assert not asks_on_the_spot("a person places a cup on the table")


def test_stepping_on_the_spot_keeps_planted_feet_and_bone_lengths():
    J = _walker()
    s = 0.1
    out = scaled_strides(J, s)
    # the root's path is scaled about its start (height kept)
    assert np.allclose(out[:, 0, [0, 2]], J[0, 0, [0, 2]] + s * (J[:, 0, [0, 2]] - J[0, 0, [0, 2]]), atol=1e-9)
    assert np.allclose(out[:, [0, 7, 8, 10, 11], 1], J[:, [0, 7, 8, 10, 11], 1], atol=1e-12)
    # the planted ankle stays where it was planted, in x and z, though the body went 3 m past it
    assert np.ptp(out[:, 7, 2]) < 1e-9 and np.ptp(out[:, 7, 0]) < 1e-9 and np.ptp(J[:, 0, 2]) > 2.9
    # the swinging ankle's reach ahead of the pelvis is a tenth of the walk's
    assert np.abs(out[:, 8, 2] - out[:, 0, 2]).max() == pytest.approx(0.1 * np.abs(J[:, 8, 2] - J[:, 0, 2]).max(),
                                                                       rel=1e-6)
    # the knees are placed for the moved ankles with the leg's own bones, bent forward
    for hip, knee, ankle in ((1, 4, 7), (2, 5, 8)):
        for a, b in ((hip, knee), (knee, ankle)):
            assert np.allclose(np.linalg.norm(out[:, a] - out[:, b], axis=1), np.linalg.norm(J[:, a] - J[:, b], axis=1),
                               atol=1e-6)
        assert ((out[:, knee] - (out[:, hip] + out[:, ankle]) / 2)[:, 2] > 0).all()
    # the feet keep their direction from the ankle; the upper body is carried by the root
    assert np.allclose(out[:, 10] - out[:, 7], J[:, 10] - J[:, 7]) and np.allclose(out[:, 11] - out[:, 8], J[:, 11] - J[:, 8])
    assert np.allclose(out[:, 16] - out[:, 0], J[:, 16] - J[:, 0])
    assert np.allclose(scaled_strides(J, 1.0), J)


def test_a_jog_asked_in_place_steps_on_the_spot(openbody):
    """The default model writes only travelling jogs (the data holds one caption of stepping in
    place): "a person jogs in place" went 7-9 m in 4 s; now it stays within half a metre, its feet
    planted and on the floor, its knees still lifting. A loop of it advances a few centimetres."""
    import torch

    from shapemove.core.generation.animate import Animation, animate
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    gen.set_captured(False)   # the codec's jog, which travels, against the same jog stepped on the spot
    whole = gen.generate_batch([Request("a person jogs in place", seconds=4, seed=0, by_parts=False)])[0]
    m = gen.generate_batch([Request("a person jogs in place", seconds=4, seed=0)])[0]
    went = lambda mm: float(np.linalg.norm(mm.joints[-1, 0, [0, 2]] - mm.joints[0, 0, [0, 2]]))  # noqa: E731
    assert went(whole) > 3.0 and went(m) < 0.6 and m.tokens is None and m.num_frames == 80
    knees = m.joints[:, [4, 5], 1]
    assert (knees.max(0) - knees.min(0)).min() > 0.15
    slide = []
    for k, j in ((2, 10), (3, 11)):   # the balls of the feet where planted
        on = (m.contacts[1:, k] > 0) & (m.contacts[:-1, k] > 0)
        slide += list(np.linalg.norm(np.diff(m.joints[:, j, [0, 2]], axis=0), axis=1)[on])
    assert len(slide) > 20 and np.mean(slide) < 0.002
    with torch.no_grad():
        v = openbody(torch.as_tensor(m.betas)[None].expand(m.num_frames, -1), torch.as_tensor(m.poses),
                     torch.as_tensor(m.transl)).vertices
    assert v[..., 1].min(1).values.min().item() > -0.005
    loop = animate(gen, Request("a person jogs in place", seed=0), Animation(loop=True))
    assert np.linalg.norm(loop.loop_advance[[0, 2]]) < 0.15
