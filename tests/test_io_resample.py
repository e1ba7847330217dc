"""Resampling to 20 fps (linear positions, slerp rotations) and the T-pose lead-in detector."""
import numpy as np
import pytest

from mocap_synth import SMPL_REST
from shapemove.core.errors import ShapeMoveError
from shapemove.core.geometry.rotations import axis_rotation
from shapemove.core.io.resample import resample_positions, resample_rotations, sample_times
from shapemove.core.io.tpose import is_tpose, tpose_lead_in


@pytest.mark.parametrize("src,n,expect", [(120, 121, 21), (120, 126, 21), (120, 127, 22), (30, 31, 21),
                                          (30, 4, 3), (20, 7, 7), (25, 26, 21), (1, 1, 1)])
def test_frame_counts(src, n, expect):
    assert len(sample_times(n, src, 20)) == expect
    assert resample_positions(np.zeros((n, 22, 3)), src, 20).shape == (expect, 22, 3)


def test_linear_motion_resampled_exactly():
    t = np.arange(91) / 30.0                     # 3 s at 30 fps
    x = np.stack([1 + 2 * t, -t, 0.5 * t], -1)[:, None, :].repeat(22, 1)
    y = resample_positions(x, 30, 20)
    t20 = np.arange(len(y)) / 20.0
    np.testing.assert_allclose(y[:, 5], np.stack([1 + 2 * t20, -t20, 0.5 * t20], -1), atol=1e-12)
    assert len(y) == 61
    with pytest.raises(ShapeMoveError):
        resample_positions(x, 0, 20)


def test_slerp_constant_angular_velocity():
    ang = np.radians(np.arange(61) * 2.0)       # 2 deg a frame at 60 fps, about Z
    R = axis_rotation("z", ang)[:, None]         # (T,1,3,3)
    out = resample_rotations(R, 60, 20)
    got = np.degrees(np.arctan2(out[:, 0, 1, 0], out[:, 0, 0, 0]))
    np.testing.assert_allclose(got, np.arange(len(out)) * 6.0, atol=1e-9)
    # halfway between frames: 45 fps -> 20 fps samples at 2.25 source frames
    out2 = resample_rotations(R[:10], 45, 20)
    np.testing.assert_allclose(np.degrees(np.arctan2(out2[1, 0, 1, 0], out2[1, 0, 0, 0])), 4.5, atol=1e-9)


def _tpose():
    j = SMPL_REST.copy()
    for side, (sh, el, wr) in ((1, (16, 18, 20)), (-1, (17, 19, 21))):
        j[el] = j[sh] + [side * 0.26, 0, 0]
        j[wr] = j[sh] + [side * 0.51, 0, 0]
    return j


def _arms_down():
    j = SMPL_REST.copy()
    for side, (sh, el, wr) in ((1, (16, 18, 20)), (-1, (17, 19, 21))):
        j[el] = j[sh] + [side * 0.03, -0.26, 0]
        j[wr] = j[sh] + [side * 0.05, -0.51, 0.02]
    return j


def test_is_tpose():
    assert is_tpose(_tpose()[None])[0]
    assert not is_tpose(_arms_down()[None])[0]
    arms_up = _tpose()
    arms_up[[18, 20, 19, 21], 1] += [0.2, 0.4, 0.2, 0.4]   # 38 deg up: no longer horizontal
    assert not is_tpose(arms_up[None])[0]
    bent = _tpose()
    bent[20] = bent[18] + [0, 0, 0.25]                     # elbows bent forward
    bent[21] = bent[19] + [0, 0, 0.25]
    assert not is_tpose(bent[None])[0]


def _walk(n, fps, start=None):
    """Arms down, walking +Z at 1.2 m/s, a little arm swing."""
    t = np.arange(n) / fps
    j = np.repeat(_arms_down()[None], n, 0)
    j[:, :, 2] += 1.2 * t[:, None]
    j[:, [20, 21], 2] += 0.1 * np.sin(2 * np.pi * t)[:, None] * [1, -1]
    return j


def test_held_tpose_then_motion_is_cut():
    fps = 30
    hold = np.repeat(_tpose()[None], 15, 0)
    hold += np.random.default_rng(0).normal(scale=0.001, size=hold.shape)  # marker jitter, ~0 velocity
    blend = np.stack([(1 - w) * _tpose() + w * _arms_down() for w in np.linspace(0, 1, 8)[1:-1]])
    clip = np.concatenate([hold, blend, _walk(60, fps)])
    cut = tpose_lead_in(clip, fps)
    assert 15 <= cut <= 15 + len(blend)
    assert not is_tpose(clip[cut:]).any()


def test_converter_rest_frame_and_blend_cut():
    """One T-pose rest frame, then a few very fast blend frames (as in CMU's BVH files)."""
    fps = 120
    walk = _walk(200, fps)
    blend = np.stack([(1 - w) * _tpose() + w * walk[0] for w in (0.3, 0.6, 0.85)])
    clip = np.concatenate([_tpose()[None], blend, walk])
    assert tpose_lead_in(clip, fps) == 4


def test_no_cut_without_tpose_or_when_moving():
    fps = 30
    assert tpose_lead_in(_walk(60, fps), fps) == 0
    airplane = np.repeat(_tpose()[None], 40, 0)
    airplane[:, :, 2] += 2.0 * np.arange(40)[:, None] / fps  # running with the arms out
    clip = np.concatenate([airplane, _walk(40, fps) + airplane[-1, 0] * [0, 0, 1]])
    assert tpose_lead_in(clip, fps) == 0
