"""AMASS .npz reader (through a real BodyModel built from hand-made arrays) and the HumanML3D
folder reader."""
import numpy as np
import pytest

from mocap_synth import SMPL_REST
from shapemove.core.body.model import BodyModel
from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.amass import load_amass
from shapemove.core.io.humanml3d import iter_humanml3d, parse_caption_line, read_split
from shapemove.core.io.mocap import load_mocap, load_smpl22


def _stick_body(name="smpl-test"):
    """A BodyModel whose 24 'vertices' are the joints (identity regressor); beta 0 stretches Y by 10%."""
    rest = np.concatenate([SMPL_REST, SMPL_REST[[20, 21]] + [[0.08, 0, 0], [-0.08, 0, 0]]]) - SMPL_REST[0]
    shapedirs = np.zeros((24, 3, 10))
    shapedirs[:, 1, 0] = 0.1 * rest[:, 1]
    return BodyModel(rest, shapedirs, np.eye(24), np.eye(24), np.array([[0, 1, 2]]), name=name), rest


def _npz(path, poses, trans, betas=None, fps=60.0, **extra):
    np.savez(path, poses=poses, trans=trans, betas=np.zeros(16) if betas is None else betas,
             mocap_framerate=np.array(fps), gender=np.array("neutral"), **extra)
    return path


def test_amass_z_up_to_y_up(tmp_path):
    body, rest = _stick_body()
    T = 3
    poses = np.zeros((T, 156))
    poses[:, 0] = np.pi / 2           # AMASS root orient: the Y-up body stood up in a Z-up world
    poses[2, 3 * 4] = np.pi / 2       # frame 2: left knee (joint 4) flexed 90 deg about its X
    trans = np.array([[0, 0, 0], [1.0, 2.0, 0.5], [0, 0, 0]])
    m = load_amass(_npz(tmp_path / "a.npz", poses, trans), body_model=body)
    assert m.fps == 60 and m.num_frames == 3 and m.up_axis == "Z" and m.names[4] == "left_knee"
    rest32 = rest.astype(np.float32).astype(np.float64)
    # Rx(90) into Z-up, then Z-up -> Y-up: the body stands as in its rest pose, facing +Z, left +X
    np.testing.assert_allclose(m.positions[0], rest32, atol=1e-6)
    # AMASS trans (x, y, z) Z-up -> (x, z, -y) Y-up
    np.testing.assert_allclose(m.positions[1] - m.positions[0], np.tile([1.0, 0.5, -2.0], (24, 1)), atol=1e-6)
    # knee flexion: the shin (0,-0.398,-0.04) turns to point backwards (-Z) and up
    shin = rest32[7] - rest32[4]
    expect = rest32[4] + np.array([shin[0], -shin[2], shin[1]])
    np.testing.assert_allclose(m.positions[2, 7], expect, atol=1e-6)
    # the stored rest offsets and local rotations reproduce the positions
    from shapemove.core.geometry.fk import forward_kinematics, joints_from_offsets
    trans_local = np.broadcast_to(m.offsets, (3, 24, 3)).copy()
    trans_local[:, 0] = m.positions[:, 0]
    posed, _ = forward_kinematics(m.rotations, joints_from_offsets(trans_local, m.parents), m.parents)
    np.testing.assert_allclose(posed, m.positions, atol=1e-6)


def test_amass_betas_only_for_smpl_family(tmp_path):
    poses = np.zeros((2, 66))
    poses[:, 0] = np.pi / 2
    betas = np.zeros(16)
    betas[0] = 1.0
    path = _npz(tmp_path / "b.npz", poses, np.zeros((2, 3)), betas=betas, fps=120)
    smpl, rest = _stick_body("smpl-test")
    other, _ = _stick_body("openbody-v1")
    a = load_amass(path, body_model=smpl)
    b = load_amass(path, body_model=other)
    assert a.meta["betas_used"] and not b.meta["betas_used"]
    head_a, head_b = a.positions[0, 15, 1] - a.positions[0, 0, 1], b.positions[0, 15, 1] - b.positions[0, 0, 1]
    assert head_a == pytest.approx(1.1 * head_b, rel=1e-5)
    # through the dispatcher, to 20 fps: 2 frames at 120 fps span 1/120 s -> one frame
    mo = load_smpl22(path, body_model=smpl)
    assert mo.rig == "smpl" and mo.num_frames == 1 and mo.fps == 20


def test_amass_errors(tmp_path):
    body, _ = _stick_body()
    p = tmp_path / "x.npz"
    np.savez(p, poses=np.zeros((2, 66)))
    with pytest.raises(ShapeMoveError, match="trans"):
        load_amass(p, body_model=body)
    _npz(p, np.full((2, 66), np.nan), np.zeros((2, 3)))
    with pytest.raises(ShapeMoveError, match="NaN"):
        load_amass(p, body_model=body)
    _npz(p, np.zeros((2, 30)), np.zeros((2, 3)))
    with pytest.raises(ShapeMoveError, match="poses"):
        load_amass(p, body_model=body)
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    with pytest.raises(ShapeMoveError):
        load_mocap(tmp_path / "junk.npz", body_model=body)


def test_amass_default_body_is_openbody(tmp_path):
    poses = np.zeros((2, 66))
    poses[:, 0] = np.pi / 2
    m = load_amass(_npz(tmp_path / "o.npz", poses, np.zeros((2, 3))))
    feet = m.positions[0, [7, 8], 1].mean()
    assert 1.2 < m.positions[0, 15, 1] - feet < 1.9  # an adult's ankle-to-head span, standing up (Y)


def test_humanml3d_folder(tmp_path):
    (tmp_path / "new_joint_vecs").mkdir()
    (tmp_path / "texts").mkdir()
    feats = np.random.default_rng(0).normal(size=(40, 263)).astype(np.float32)
    np.save(tmp_path / "new_joint_vecs" / "000001.npy", feats)
    (tmp_path / "texts" / "000001.txt").write_text(
        "a man walks forward.#a/DET man/NOUN walk/VERB forward/ADV#0.0#0.0\n"
        "a person steps ahead then #2 stops#a/DET person/NOUN#1.5#3.25\n")
    (tmp_path / "train.txt").write_text("000001\n000002\n")
    (tmp_path / "val.txt").write_text("")
    assert read_split(tmp_path, "train") == ["000001", "000002"]
    clips = list(iter_humanml3d(tmp_path, "train"))
    assert [c.id for c in clips] == ["000001"]  # 000002 has no files: skipped
    np.testing.assert_array_equal(clips[0].features, feats)
    c0, c1 = clips[0].captions
    assert c0.text == "a man walks forward." and c0.tokens[1] == "man/NOUN" and (c0.start, c0.end) == (0, 0)
    assert c1.text == "a person steps ahead then #2 stops" and (c1.start, c1.end) == (1.5, 3.25)
    with pytest.raises(ShapeMoveError):
        list(iter_humanml3d(tmp_path, "train", skip_missing=False))
    with pytest.raises(ShapeMoveError, match="split file missing"):
        read_split(tmp_path, "test")
    with pytest.raises(ShapeMoveError):
        parse_caption_line("no separators here")
    assert parse_caption_line("x#t#nan#nan").start == 0.0
