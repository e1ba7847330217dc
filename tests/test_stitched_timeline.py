"""stitched_timeline: a timeline of finished motions, each segment its own choice among samples and
captured takes, joined without a jump (docs/animation.md, "Timeline of prompts")."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.generation.stitched_timeline import BLEND, FADE_SHARE, MAX_BLEND, joined, stitch
from shapemove.core.generation.track import rotate_y
from walk_track import walk

pytestmark = pytest.mark.usefixtures("one_thread")


def _direction(joints, a, b):
    """Yaw (0 along +Z) of the root's travel from frame a to b."""
    d = joints[b, 0] - joints[a, 0]
    return float(np.arctan2(d[0], d[2]))


def test_the_next_segment_starts_where_and_as_the_last_one_ends():
    prev = walk(40, 0.02, turn=0.02).joints          # ends heading 39 * 0.02 = 0.78 rad, at some x, z
    nxt = walk(30, 0.03, seed=1).joints              # another pose, straight along +Z from the origin
    out = joined(prev, nxt)
    assert out.shape == nxt.shape
    # the first frame continues prev by the next segment's own first step (0.03 m)
    assert np.linalg.norm(out[0, 0] - prev[-1, 0]) == pytest.approx(0.03, abs=1e-6)
    assert np.abs(out[0] - prev[-1]).max() <= 0.03 + 1e-6
    # after the fade: the next segment itself, moved rigidly (distances between all joints kept),
    # travelling the way prev was going
    d = lambda j: np.linalg.norm(j[:, :, None] - j[:, None], axis=-1)  # noqa: E731
    n = next(k for k in range(len(out)) if np.allclose(d(out[k:]), d(nxt[k:]), atol=1e-9))   # the fade's length
    assert BLEND <= n <= min(MAX_BLEND, len(nxt)) and not np.allclose(d(out[:1]), d(nxt[:1]))
    assert _direction(out, n, 29) == pytest.approx(0.78, abs=0.08)
    assert np.linalg.norm(out[29, 0] - out[n, 0]) == pytest.approx(0.03 * (29 - n), abs=1e-6)
    # the fade (out less the next segment placed rigidly) moves no joint more than FADE_SHARE of its
    # 99th-percentile step in the two segments a frame
    placed = rotate_y(nxt - nxt[n, 0], _direction(out, n, 29) - _direction(nxt, n, 29)) + out[n, 0]
    np.testing.assert_allclose(out[n:], placed[n:], atol=1e-6)
    fade_step = np.linalg.norm(np.diff(out - placed, axis=0), axis=-1)
    p99 = np.maximum(np.percentile(np.linalg.norm(np.diff(np.concatenate([prev, nxt]), axis=0), axis=-1), 99, axis=0), 0.005)
    assert (fade_step <= FADE_SHARE * p99 + 1e-6).all()


def test_stitch_joins_in_order_with_the_bounds_and_contacts():
    a, b, c = walk(40, 0.02), walk(30, 0.03, turn=0.03, seed=1), walk(20, 0.0, seed=2)
    track, bounds = stitch([a.joints, b.joints, c.joints], [a.contacts, b.contacts, c.contacts])
    assert bounds.tolist() == [[0, 40], [40, 70], [70, 90]]
    np.testing.assert_array_equal(track.joints[:40], a.joints)           # the first segment as it is
    np.testing.assert_array_equal(track.contacts[40:70], b.contacts)
    # the standing third segment stands where the turning second one ended
    assert np.linalg.norm(track.joints[70:, 0, [0, 2]] - track.joints[69, 0, [0, 2]], axis=1).max() < 0.05
    with pytest.raises(ShapeMoveError, match="joints and contacts"):
        stitch([a.joints], [])


@pytest.fixture(scope="module")
def gen():
    from shapemove.core.generation.generate import Generator

    return Generator(None)


@pytest.fixture(scope="module")
def timeline(gen):
    from shapemove.core.generation.sequence import generate_sequence

    segs = [("a person walks forward", 3.0), ("a man throws a front kick", 2.0), ("a person stands still", 2.0)]
    return generate_sequence(gen, segs, seed=0)


def test_each_segment_is_its_own_choice_among_samples_and_takes(gen, timeline):
    """The default model (captured takes on): the kick segment is a captured kick, played as
    performed (the kicking ankle rises over half a metre), between a walk and a stand; no seam jumps
    (the #56 bar: no joint's step across a seam over 1.5x its 99th percentile inside the segments)."""
    from shapemove.core.generation.sequence import boundary_report
    from shapemove.core.generation.stitched_timeline import is_stitched

    m = timeline
    assert m.segment_bounds.tolist() == [[0, 60], [60, 100], [100, 140]] and is_stitched(m)
    kinds = m.provenance.split("; ")
    assert len(kinds) == 3 and [k.split(":")[0] for k in kinds] == ["segment 1", "segment 2", "segment 3"]
    assert kinds[1].startswith("segment 2: captured:") and "kick" in kinds[1].lower()
    ankles = m.joints[:, [7, 8], 1]
    floor = ankles[:60].min()
    assert ankles[60:100].max() - floor > 0.5 and ankles[:60].max() - floor < 0.3
    root = m.joints[:, 0, [0, 2]]
    assert np.linalg.norm(root[59] - root[0]) > 2.0                              # walked
    assert np.linalg.norm(np.diff(root[120:140], axis=0), axis=1).mean() * m.fps < 0.1   # stands still
    assert boundary_report(m)["jump_ratio"] <= 1.5
    assert m.features is not None and len(m.features) == m.num_frames - 1


def test_a_stitched_timeline_on_another_body_a_new_strip_and_on_disk(gen, timeline, tmp_path):
    from shapemove.core.generation.sequence import regenerate_segment
    from shapemove.core.generation.stitched_timeline import is_stitched
    from shapemove.core.scene.motion_file import load_motion, save_motion

    tall = np.zeros(10, np.float32)
    tall[0] = 2.0                                                  # a taller body (this body model: beta 0 > 0)
    other = gen.redecode(timeline, tall)
    assert other.segment_bounds.tolist() == timeline.segment_bounds.tolist() and other.provenance == timeline.provenance
    height = lambda m: float(m.joints[0, 15, 1] - m.joints[0, [10, 11], 1].min())  # noqa: E731  head over feet
    assert height(other) > height(timeline) + 0.05
    strip = regenerate_segment(gen, timeline, 1, seed=3, prompt="a person waves with the right hand")
    assert strip.segment_prompts[1] == "a person waves with the right hand" and is_stitched(strip)
    assert strip.segment_bounds.tolist() == timeline.segment_bounds.tolist()
    kinds = strip.provenance.split("; ")
    assert kinds[0] == timeline.provenance.split("; ")[0] and kinds[2] == timeline.provenance.split("; ")[2]
    assert np.abs(strip.joints[:50] - timeline.joints[:50]).max() < 0.05     # the walk kept (planted again)
    assert strip.joints[60:100, 21, 1].max() > strip.joints[60:100, 15, 1].min()   # the right wrist over the head
    back = load_motion(save_motion(tmp_path / "t.npz", timeline))
    assert is_stitched(back) and back.provenance == timeline.provenance
    assert back.segment_prompts == timeline.segment_prompts


def test_sequence_no_library_gives_the_timeline_of_codes(tmp_path, capsys):
    """`sequence` names each segment's source; `--no-library` makes the timeline of codes."""
    from shapemove.cli import main
    from shapemove.core.scene.motion_file import load_motion

    argv = ["sequence", "--prompt", "a person walks forward", "--seconds", "1.2", "--prompt", "a person kicks",
            "--seconds", "1.2", "--candidates", "1"]
    assert main([*argv, "--out", str(tmp_path / "s.npz")]) == 0
    out = capsys.readouterr().out
    stitched = load_motion(tmp_path / "s.npz")
    assert stitched.num_tokens == 0 and stitched.provenance.count("segment ") == 2
    assert "[captured: " in out or "[generated" in out
    try:
        assert main([*argv, "--no-library", "--out", str(tmp_path / "c.npz")]) == 0
    finally:   # the process's one loaded generator, as the other commands leave it
        from shapemove.core.generation.loaded_generator import loaded_generator

        loaded_generator(None, None).set_captured(True)
    codes = load_motion(tmp_path / "c.npz")
    assert codes.num_tokens == 12 and codes.segment_bounds.tolist() == [[0, 24], [24, 48]]
