"""Issue #24's measurements on a real walk (tiny_dataset): the root re-derived from the planted feet
(core/motion/root_from_feet.py), the gait measures (core/eval/gait.py) and the codec's speed and
shape conditioning with the shipped SA-VAE (core/eval/speed.py)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.eval.gait import cadence, leg_length, mean_speed, stride_length, swing, velocity_correlation
from shapemove.core.motion.contacts import detect_contacts, runs
from shapemove.core.motion.features import joints_from_features
from shapemove.core.motion.root_from_feet import feet_root_path, root_from_feet

pytestmark = pytest.mark.usefixtures("one_thread")
WALK = "dataset-1_walk_feminine_001"
SAVAE = Path(__file__).resolve().parents[1] / "weights" / "default" / "savae.pt"


@pytest.fixture(scope="module")
def walk(tiny_dataset):
    feats = np.load(tiny_dataset / "new_joint_vecs" / f"{WALK}.npy").astype(np.float64)
    joints = joints_from_features(feats)
    return {"joints": joints, "contacts": detect_contacts(joints), "feats": feats,
            "norm": np.load(tiny_dataset / "norm_joint_vecs" / f"{WALK}.npy"),
            "betas": np.load(tiny_dataset / "betas" / f"{WALK}.npy").reshape(-1)}


def _travel(path) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=-1).sum())


def test_feet_reproduce_a_real_walks_travel(walk):
    j = walk["joints"]
    real = _travel(j[:, 0, [0, 2]])
    assert real > 3.0                                                        # a real walk across the room
    derived = feet_root_path(j, walk["contacts"])
    assert derived.shape == (len(j), 2)
    assert np.allclose(derived[0], j[0, 0, [0, 2]])
    assert 0.97 < _travel(derived) / real < 1.03                             # within a few %
    # the end point too: the path goes where the walk went, not just as far
    assert np.linalg.norm(derived[-1] - j[-1, 0, [0, 2]]) < 0.05 * real


def test_feet_reproduce_a_real_runs_travel(tiny_dataset):
    """A run has flights (no foot down): by default they keep the run's own root step; interpolated
    between the plants instead, the travel comes out short (the stance's braking is averaged in)."""
    j = joints_from_features(np.load(tiny_dataset / "new_joint_vecs" / "dataset-1_run_happy_001.npy").astype(np.float64))
    c = detect_contacts(j)
    assert (c.sum(1) == 0).mean() > 0.2                                      # airborne a fifth of the time
    real = _travel(j[:, 0, [0, 2]])
    keep = _travel(feet_root_path(j, c)) / real
    interpolated = _travel(feet_root_path(j, c, flight="interpolate")) / real
    assert 0.97 < keep < 1.03
    assert interpolated < keep - 0.03
    with pytest.raises(ShapeMoveError, match="flight"):
        feet_root_path(j, c, flight="glide")


def test_feet_restore_a_shrunk_root(walk):
    """The codec's failure, made by hand: the legs step full size while the root travels 0.8x
    (planted feet skate backward). The feet give the travel back; the pose is untouched."""
    j = walk["joints"]
    shrunk = j.copy()
    root = j[:, 0, [0, 2]]
    shrunk[..., [0, 2]] -= (0.2 * (root - root[0]))[:, None]                 # every joint moves with the root
    assert _travel(shrunk[:, 0, [0, 2]]) / _travel(root) == pytest.approx(0.8, abs=1e-6)
    fixed = root_from_feet(shrunk, walk["contacts"])
    assert 0.97 < _travel(fixed[:, 0, [0, 2]]) / _travel(root) < 1.03
    rel = lambda x: x - x[:, :1]                                             # noqa: E731
    assert np.allclose(rel(fixed), rel(shrunk))                              # pose kept
    assert np.allclose(fixed[..., 1], shrunk[..., 1])                        # heights kept
    # a planted heel stays put: its slide over each contact run is a few mm, not the 20 % skate
    heel = 0                                                                 # CONTACT_IDS[0] = left ankle 7
    slide_fixed = [np.linalg.norm(fixed[e - 1, 7, [0, 2]] - fixed[s, 7, [0, 2]])
                   for s, e in runs(walk["contacts"][:, heel]) if e - s >= 4]
    slide_shrunk = [np.linalg.norm(shrunk[e - 1, 7, [0, 2]] - shrunk[s, 7, [0, 2]])
                    for s, e in runs(walk["contacts"][:, heel]) if e - s >= 4]
    assert slide_fixed and np.mean(slide_fixed) < 0.02 < np.mean(slide_shrunk)


def test_feet_refuse_bad_input(walk):
    j = walk["joints"]
    with pytest.raises(ShapeMoveError, match="contacts"):
        root_from_feet(j, walk["contacts"][:-1])
    with pytest.raises(ShapeMoveError, match="no foot is planted"):
        root_from_feet(j, np.zeros((len(j), 4), np.uint8))
    with pytest.raises(ShapeMoveError, match="joints"):
        root_from_feet(j[:, :10], walk["contacts"])


def test_gait_measures_on_a_real_walk(walk):
    j, c = walk["joints"], walk["contacts"]
    speed = mean_speed(j)
    assert 0.8 < speed < 2.0                                                 # m/s, a walk
    # cadence from the ankles' fore-aft swing agrees with the heel strikes counted in the contacts
    strikes = sum(len(runs(c[:, k])) for k in (0, 1))                        # heel runs, both feet
    counted = strikes / ((len(j) - 1) / 20.0)
    assert cadence(j) == pytest.approx(counted, rel=0.15)
    assert 1.4 < cadence(j) < 2.4                                            # steps per second
    assert stride_length(j) == pytest.approx(speed / (cadence(j) / 2))
    assert 0.3 < swing(j) < 0.9                                              # feet ~0.5 m apart at full reach
    half = j.copy()
    half[:, [7, 8], 2] = 0.5 * (j[:, [7, 8], 2] - j[:, :1, 2]) + j[:, :1, 2]  # ankles half as far from the root
    assert swing(half) == pytest.approx(0.5 * swing(j), rel=0.15)           # (the walk is along z)
    assert velocity_correlation(j, j) == pytest.approx(1.0)
    assert velocity_correlation(j, 0.5 * j) == pytest.approx(1.0)            # a scaled copy: same surges
    shifted = np.roll(j, 5, axis=0)                                          # a quarter step late: disagrees
    assert velocity_correlation(j[10:], shifted[10:]) < 0.9


@pytest.fixture(scope="module")
def codec(openbody):
    if not SAVAE.is_file():
        pytest.skip(f"{SAVAE} missing")
    from shapemove.core.generation.retarget import load_vae

    return load_vae(SAVAE, openbody)


def test_decoded_walk_speed_is_measured_on_both_roots(walk, codec, openbody):
    from shapemove.core.eval.speed import clip_speeds

    r = clip_speeds(codec, openbody, walk["norm"], walk["feats"], walk["betas"], feet=True)
    assert r["frames"] == (len(walk["norm"]) // 4) * 4
    assert r["orig_mps"] == pytest.approx(mean_speed(walk["joints"][:r["frames"]]), rel=1e-6)
    for kind in ("decoded", "final", "feet", "feet_final"):
        assert 0.5 < r[f"{kind}_mps"] / r["orig_mps"] < 1.2
        assert -1 <= r[f"{kind}_corr"] <= 1
        assert 0.5 < r[f"{kind}_swing_m"] / r["orig_swing_m"] < 1.2
    # planting and IK move the feet, not the travel: the final root keeps the decoded speed
    assert r["final_mps"] == pytest.approx(r["decoded_mps"], rel=0.03)


def test_shape_changes_stride_not_cadence(walk, codec, openbody):
    from shapemove.core.eval.speed import shape_bodies, shape_gait
    from shapemove.core.generation.retarget import encode_take

    bodies = shape_bodies(openbody)
    legs = {k: leg_length(openbody, b) for k, b in bodies.items()}
    assert legs["tall"] / legs["short"] > 1.25                               # really different legs
    g = shape_gait(encode_take(codec, walk["norm"]), codec, openbody, bodies)
    for kind in ("decoded", "final"):
        assert g[f"{kind}_cadence_ratio"] == pytest.approx(1.0, abs=0.05)    # same steps per second
        assert g[f"{kind}_stride_ratio"] > 1.15                              # longer legs, longer strides
        # close to the leg-length ratio (the shipped codec: ~0.93 of it)
        assert 0.85 < g[f"{kind}_stride_ratio"] / g["leg_ratio"] < 1.1
