"""Mirror images of clips (core/data/mirror.py): left and right swapped, in the joints, the
rotations, the features and the captions."""
import json
import shutil

import numpy as np
import pytest
import torch

from shapemove.core.body.skeleton import PARENTS
from shapemove.core.data import mirror as mr
from shapemove.core.geometry.fk import forward_kinematics
from shapemove.core.geometry.rotations import axis_angle_to_matrix
from shapemove.core.motion.features import feature_slices


def test_side_words_swap_and_swap_back():
    s = "A man raises his Left hand, turns clockwise and kicks with the right foot; left-handed throws."
    m = mr.swap_sides(s)
    assert m == "A man raises his Right hand, turns counter-clockwise and kicks with the left foot; right-handed throws."
    assert mr.swap_sides(m) == s
    assert mr.swap_sides("walks in an anticlockwise circle") == "walks in an clockwise circle"
    assert mr.swap_sides("no sides here, just a bright light") == "no sides here, just a bright light"


def test_mirror_is_a_reflection_consistent_with_fk(openbody):
    rng = np.random.default_rng(0)
    betas = rng.standard_normal(10).astype(np.float32)
    rest = openbody.rest_joints(torch.as_tensor(betas)[None])[0].numpy().astype(np.float64)
    # the body is symmetric, so a mirrored motion can stay on the same betas
    assert np.abs(mr.mirror_joints(rest[None])[0] - rest).max() < 5e-4
    R = axis_angle_to_matrix(rng.standard_normal((6, 24, 3)) * 0.6)
    j, _ = forward_kinematics(R, rest, PARENTS)
    jm, _ = forward_kinematics(mr.mirror_rotations(R), rest, PARENTS)
    assert np.abs(jm - mr.mirror_joints(j)).max() < 5e-4          # M R M is the rotation of the mirror
    np.testing.assert_allclose(mr.mirror_rotations(mr.mirror_rotations(R)), R, atol=1e-12)
    assert np.abs(jm - j).max() > 0.05                           # and it is not the identity


def test_mirrored_walk_is_a_walk_of_the_same_speed(tiny_dataset, tmp_path, openbody):
    data = tmp_path / "d"
    shutil.copytree(tiny_dataset, data)
    sources_own = None
    for p in sorted((data / "meta").glob("*.json")):   # make every clip a training clip for this test
        m = json.loads(p.read_text())
        m["split"] = "train"
        if sources_own is None and "walk" not in m["id"] and "wave" not in m["id"]:
            sources_own = m["id"]  # as DeepMimic's own *_mirror motions say of themselves
            m.setdefault("labels", {})["mirrored"] = True
        p.write_text(json.dumps(m))
    written = mr.mirror_dataset(data, body=openbody, verbose=False)
    assert sources_own is not None and sources_own + mr.SUFFIX not in written   # its mirror image is its source
    assert not (data / "meta" / f"{sources_own}{mr.SUFFIX}.json").exists()
    cid = "dataset-1_walk_feminine_001"
    assert cid + mr.SUFFIX in written and not any(w.endswith(mr.SUFFIX + mr.SUFFIX) for w in written)
    f = np.load(data / "new_joint_vecs" / f"{cid}.npy")
    g = np.load(data / "new_joint_vecs" / f"{cid}{mr.SUFFIX}.npy")
    v, w = f[:, feature_slices["root_lin_vel"]], g[:, feature_slices["root_lin_vel"]]
    speed = np.linalg.norm(v, axis=1).mean()
    assert speed > 0.02                                            # it walks
    assert np.linalg.norm(w, axis=1).mean() == pytest.approx(speed, rel=1e-3)
    np.testing.assert_allclose(w[:, 1], v[:, 1], atol=2e-3)        # forward speed kept
    np.testing.assert_allclose(w[:, 0], -v[:, 0], atol=2e-3)       # sideways drift flipped
    np.testing.assert_allclose(g[:, feature_slices["root_rot_vel"]], -f[:, feature_slices["root_rot_vel"]], atol=2e-3)
    # the left-hand wave becomes a right-hand wave, in its captions and in which hand moves
    wave = "dataset-2_wave-left-hand_elderly_001"
    caps = (data / "texts" / f"{wave}{mr.SUFFIX}.txt").read_text()
    assert "right" in caps and "left" not in caps
    j = np.load(data / "new_joints" / f"{wave}.npy")
    jm = np.load(data / "new_joints" / f"{wave}{mr.SUFFIX}.npy")
    travel = lambda x, k: np.linalg.norm(np.diff(x[:, k] - x[:, 0], axis=0), axis=-1).sum()  # noqa: E731
    assert travel(j, 20) > 1.5 * travel(j, 21)                     # the left wrist (20) waves
    assert travel(jm, 21) > 1.5 * travel(jm, 20)                   # the mirror waves the right (21)
    # mirrored twice is the identity, features included
    arrays = mr.mirror_arrays(mr.ClipProcessor(openbody), data, cid + mr.SUFFIX)
    np.testing.assert_allclose(arrays["new_joints"], np.load(data / "new_joints" / f"{cid}.npy"), atol=1e-5)
    np.testing.assert_allclose(arrays["new_joint_vecs"], f, atol=1e-4)
    # the features' own mirror (no joints, no IK) is the builder's mirrored clip, and twice the identity
    for name in (cid, wave):
        own = np.load(data / "new_joint_vecs" / f"{name}.npy")
        built = np.load(data / "new_joint_vecs" / f"{name}{mr.SUFFIX}.npy")
        np.testing.assert_allclose(mr.mirror_features(own), built, atol=2e-4)
        np.testing.assert_array_equal(mr.mirror_features(mr.mirror_features(own)), own)
    assert np.abs(mr.mirror_features(f) - f).max() > 0.1
    meta = json.loads((data / "meta" / f"{cid}{mr.SUFFIX}.json").read_text())
    assert meta["mirror_of"] == cid and meta["split"] == "train"
