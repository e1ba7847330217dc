"""A timeline's seams paced (core/generation/seam_pace.py): the decoder's transition between two
segments' codes re-timed over the frames around the seam, no faster than the segments move."""
from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.usefixtures("one_thread")


def _track(T=80, seam=40, jump=0.3):
    """(T,22,3) joints walking along +Z at 2 cm a frame, the right wrist (21) swinging 5 cm a
    frame, and at ``seam`` the wrist going ``jump`` m up in one frame."""
    t = np.arange(T, dtype=np.float64)
    J = np.zeros((T, 22, 3))
    J[:, :, 2] = 0.02 * t[:, None]
    J[:, 21, 0] = 0.05 * np.abs(((t / 8) % 2) - 1) * 8
    J[seam:, 21, 1] += jump
    return J


def test_a_jump_at_a_seam_is_spread_over_the_frames_around_it():
    from shapemove.core.generation.seam_pace import paced_seams, seam_steps, steps

    J = _track()
    contacts = np.zeros((80, 4), np.uint8)
    contacts[:, 0] = (np.arange(80) // 10) % 2
    bounds = np.array([[0, 40], [40, 80]])
    assert seam_steps(J, [40])[0] > 3.0                        # 0.3 m against the wrist's 0.05-0.06 m
    out, con = paced_seams(J, contacts, bounds)
    assert seam_steps(out, [40])[0] <= 1.5
    assert out.shape == J.shape and con.shape == contacts.shape
    moved = np.flatnonzero(np.abs(out - J).max(axis=(1, 2)) > 1e-9)
    assert moved.min() >= 40 - 12 and moved.max() <= 40 + 12    # only the window around the seam
    np.testing.assert_allclose(out[[0, -1]], J[[0, -1]])
    # the same poses in the same order: the wrist's height only rises, the root keeps its line
    assert (np.diff(out[:, 21, 1]) >= -1e-12).all() and np.allclose(out[:, 0, 0], 0.0)
    assert steps(out)[:, 0].max() <= 2.0 * 0.02                 # the root at most twice its pace
    assert set(np.unique(con)) <= {0, 1}
    assert paced_seams(_track(jump=0.0), contacts, bounds) is None   # a smooth seam is left alone


def test_a_sit_then_a_wave_has_no_pop_at_the_seam():
    """"a person sits down" 3 s -> "a person waves with the right hand" 2 s (seed 7): the decoder
    swings the arm up at the seam at 2.7x its joints' 99th-percentile step inside the segments;
    played, the worst step near the seam is at most 1.5x."""
    from shapemove.core.generation.generate import Generator
    from shapemove.core.generation.seam_pace import seam_steps
    from shapemove.core.generation.sequence import boundary_report, generate_sequence
    from shapemove.core.generation.track import decoded_track

    gen = Generator(None)
    gen.set_captured(False)   # a timeline of codes (the decoder's own seam)
    m = generate_sequence(gen, [("a person sits down", 3.0), ("a person waves with the right hand", 2.0)], seed=7)
    track, _ = decoded_track([int(t) for t in m.tokens], gen.vae, gen.body, m.betas)
    assert seam_steps(track.joints, [60])[0] > 1.8
    assert boundary_report(m)["jump_ratio"] <= 1.5
    assert m.segment_bounds.tolist() == [[0, 60], [60, 100]]
