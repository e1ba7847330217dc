"""A captured gait on a bend is played on a straight line (generation/straight_gait.py)."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from shapemove.core.geometry.rotations import axis_angle_to_matrix, yaw_matrix
from shapemove.core.generation.straight_gait import lean, straightened

pytestmark = pytest.mark.usefixtures("one_thread")


def _arc(openbody, radius=2.0, speed=1.4, frames=60, bob=0.03, tilt=0.0):
    """A body going round a left bend at ``speed`` m/s (20 fps), facing along it, its pelvis bobbing
    ``bob`` m, leaning ``tilt`` radians into the bend: local rotations (the root's only), root path
    and posed joints."""
    rest = openbody.rest_joints(torch.zeros(1, 10))[0, :22].numpy().astype(np.float64)
    s = speed / 20 * np.arange(frames)
    theta = s / radius                                         # heading gained: the left turn
    root = np.stack([radius * (1 - np.cos(theta)), 0.9 + bob * np.sin(2 * np.pi * np.arange(frames) / 10),
                     radius * np.sin(theta)], axis=1)
    Y = yaw_matrix(theta) @ axis_angle_to_matrix([0.0, 0.0, -tilt])   # facing +Z, leaning to its left (+X)
    rot = np.repeat(np.eye(3)[None, None], 24, 1).repeat(frames, 0)
    rot[:, 0] = Y
    return rot, root, _posed(rest, rot, root)


def _posed(rest, rot, root):
    """The joints of a body whose root turns by ``rot[:, 0]`` and every other joint rests."""
    return np.einsum("tij,kj->tki", rot[:, 0], rest - rest[0]) + root[:, None]


def test_a_bend_is_taken_off_and_its_steps_kept(openbody):
    rot, root, J = _arc(openbody)
    assert np.degrees(np.arctan2(root[-1, 0], root[-1, 2])) > 20            # the take turns as it goes
    r, path = straightened(rot, root, J)
    assert r.shape == rot.shape and path.shape == root.shape
    d = path[-1, [0, 2]] - path[0, [0, 2]]
    across = np.abs(np.cross(d / np.linalg.norm(d), path[:, [0, 2]] - path[0, [0, 2]]))
    assert across.max() < 0.02     # on one line (bowed 1.5 cm: the smoothed heading lags at the ends)
    arc = 1.4 / 20 * (len(root) - 1)
    assert abs(np.linalg.norm(d) - arc) < 0.02 and np.linalg.norm(d) > 0.97 * arc   # as far as it went round
    assert abs(np.degrees(np.arctan2(d[0], d[1]))) < 5     # the way the first frame faced (4 degrees: the same lag)
    assert np.allclose(path[:, 1], root[:, 1])                              # the bob kept
    assert np.abs(r[:, 0] - rot[0, 0]).max() < 0.05                         # facing as at the first frame
    assert np.array_equal(r[:, 1:], rot[:, 1:].astype(np.float32))          # every other joint as performed


def test_a_lean_into_the_bend_is_stood_upright(openbody):
    rest = openbody.rest_joints(torch.zeros(1, 10))[0, :22].numpy().astype(np.float64)
    rot, root, J = _arc(openbody, tilt=np.radians(10))
    assert np.degrees(lean(J)).mean() == pytest.approx(10, abs=0.5)          # the neck 10 degrees to its left
    r, path = straightened(rot, root, J)
    assert np.abs(np.degrees(lean(_posed(rest, r, path)))).max() < 0.5       # over the feet


def test_a_straight_take_is_left_as_it_is(openbody):
    rot, root, J = _arc(openbody, radius=1e6)
    r, path = straightened(rot, root, J)
    assert np.abs(path - root).max() < 1e-4 and np.abs(r - rot).max() < 1e-4


def test_a_plain_jog_plays_a_captured_jog_straight_and_on(openbody):
    """Asked a plain jog, the library's jogs round a left bend (HDM05, four steps) are played
    straight and looped; asked to jog in a circle, they keep their bend and are held."""
    from shapemove.core.generation.generate import Generator
    from shapemove.core.generation.track import headings, root_centre

    gen = Generator(None, body=openbody)
    i = gen.pool.ids.index("HDM_bd_jogLeftCircle4StepsRstart_001_120")
    bent = gen.pool.window(i, 80, seed=0)
    w = gen.pool.window(i, 80, seed=0, straight=True)
    assert bent.held > 20 and bent.looped == 0                               # 2 s of jog, then standing
    assert w.held == 0 and w.looped > 20 and len(w.root) == 80               # its last cycle again
    J = gen.pool.proc.pose_on(w.rotations, w.root, gen.pool.take(i)["betas"], 1.0, w.contacts)
    h = np.degrees(np.unwrap(headings(J)))
    assert np.ptp(h) < 15                                                    # bent: 69 degrees in 2 s
    c = root_centre(J)
    d = c[-1] - c[0]
    across = np.abs(np.cross(d / np.linalg.norm(d), c - c[0]))
    assert np.linalg.norm(d) > 4.5 and across.max() < 0.3                    # 4 s of jog on a line


def test_which_words_ask_a_gait_on_a_line():
    from shapemove.core.generation.straight_gait import straight_asked
    from shapemove.core.plan.words import read_words

    for text in ("a man jogs", "someone trots along slowly", "a woman walks forward quickly", "he runs"):
        assert straight_asked(read_words(text)), text
    for text in ("she jogs in a circle", "a man jogs to the left", "he runs backwards", "she walks sideways",
                 "a man jogs in place", "someone turns around", "a woman jogs while waving", "a man waves",
                 "a man walks 3 metres and stops"):
        assert not straight_asked(read_words(text)), text


def _there_and_back(openbody, frames=120, turn_at=60, turn_frames=10):
    """A body walking +Z, turning round (180 degrees over ``turn_frames``) and walking back."""
    rest = openbody.rest_joints(torch.zeros(1, 10))[0, :22].numpy().astype(np.float64)
    t = np.arange(frames)
    theta = np.pi * np.clip((t - turn_at) / turn_frames, 0.0, 1.0)
    step = 1.2 / 20 * np.stack([np.sin(theta), np.zeros(frames), np.cos(theta)], 1)
    root = np.cumsum(step, 0) + [0.0, 0.9, 0.0]
    rot = np.repeat(np.eye(3)[None, None], 24, 1).repeat(frames, 0)
    rot[:, 0] = yaw_matrix(theta)
    return _posed(rest, rot, root)


def test_a_take_that_turns_round_plays_its_longest_way_along_a_line(openbody):
    from shapemove.core.generation.straight_gait import LINE_BAND, line_stretch

    J = _there_and_back(openbody, frames=150, turn_at=50)
    lo, hi = line_stretch(J)
    assert lo > 50 and hi == 150                       # the way back (95+ frames) is longer than the way there
    assert 150 - lo == pytest.approx(150 - 50 - 10 * (1 - LINE_BAND / np.pi), abs=4)   # from 45 degrees off its end
    lo, hi = line_stretch(_there_and_back(openbody, frames=150, turn_at=100))
    assert lo == 0 and 100 <= hi <= 106                # the way there, up to where it has turned by 45 degrees
    assert line_stretch(_there_and_back(openbody, frames=80, turn_at=200)) == (0, 80)   # never turns: whole


def test_a_line_is_asked_of_one_gait_forward():
    from shapemove.core.generation.straight_gait import line_asked
    from shapemove.core.plan.words import read_words

    for text in ("a soldier marches forward", "a man limps along", "a zombie shambles", "she marches"):
        assert line_asked(read_words(text)), text
    for text in ("a man limps in a circle", "a soldier marches in place", "she marches and waves",
                 "a man marches to the left", "a man waves", "a man marches, then turns around"):
        assert not line_asked(read_words(text)), text


def test_the_march_goes_forward_and_never_turns_round():
    """CMU 105_19, the data's one march, goes up the room, turns round at 7 s and comes back: asked
    "marches forward" it marched 8.4 m and ended 1.6 m from where it started; now it plays the way
    there (looped on its last stride where asked for longer)."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    for seconds in (None, 12.0):
        m = gen.generate_batch([Request("a soldier marches forward", seconds=seconds, seed=0)])[0]
        assert "cmu_105_19" in m.provenance and "along a line" in m.provenance, m.provenance
        p = m.joints[:, 0, [0, 2]]
        path = np.linalg.norm(np.diff(p, axis=0), axis=1).sum()
        assert np.linalg.norm(p[-1] - p[0]) > 0.95 * path > 4.0, (path, p[-1] - p[0])   # straight on
