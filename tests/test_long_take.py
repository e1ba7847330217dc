"""Long takes in bounded memory (issue 28): a long take built here from a short real Bandai walk
(``bench/long_take_input.py``). The windowed steps (joints without the mesh, the ground probe, the IK,
the SA-VAE encoder) give what one pass over the whole take gives, across window seams, and
``retarget --naive`` needs about the same memory for a 90 s take as for a 30 s one (it grew by
~2 GB a minute before: a 93 s take needed 3.6 GB). The 10-minute case is ``bench long_take``."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import torch

from shapemove.bench.long_take_input import walk_path, write_long_take

pytestmark = pytest.mark.usefixtures("one_thread")

from shapemove.bench.long_take import PEAK_WRAPPER as RUN_WITH_PEAK  # noqa: E402  (prints PEAK_KB, the run's VmHWM)


@pytest.fixture(scope="module")
def takes(mocap_root, tmp_path_factory):
    d = tmp_path_factory.mktemp("long_take")
    return {s: write_long_take(walk_path(mocap_root), d / f"walk_{s}s.bvh", s, 30.0) for s in (30, 90)}


@pytest.fixture(scope="module")
def joints(takes, openbody):
    from shapemove.core.generation.retarget import source_joints

    j, _ = source_joints(takes[90], openbody)
    return j


def test_long_take_is_a_continuous_walk(joints):
    """The take is 90 s at 20 fps after reading, and it walks on: no jump back at the seams."""
    assert 1795 <= len(joints) <= 1801  # 90 s at 20 fps (the header's 7-digit frame time may drop the last)
    step = np.linalg.norm(np.diff(joints[:, 0, [0, 2]], axis=0), axis=-1)
    assert step.max() < 0.15  # m per frame at 20 fps (3 m/s): never teleports
    assert np.linalg.norm(joints[-1, 0, [0, 2]] - joints[0, 0, [0, 2]]) > 60  # ~1.3 m/s for 90 s


def test_windowed_steps_equal_one_pass(joints, openbody):
    from shapemove.core.body.ik import solve_ik
    from shapemove.core.body.kinematics import posed_joints
    from shapemove.core.body.soles import GroundProbe

    betas = np.zeros(10, np.float32)
    betas[0] = 1.5
    rest = openbody.rest_joints(torch.as_tensor(betas)[None])[0].numpy()
    part = joints[:900]  # 45 s: 3 seams of 256-frame windows
    one = solve_ik(part, rest, refine_iters=4, window=10**6)
    win = solve_ik(part, rest, refine_iters=4, window=256)
    np.testing.assert_allclose(win.rotations, one.rotations, atol=1e-6)
    np.testing.assert_allclose(win.transl, one.transl, atol=1e-6)
    assert abs(win.mean_error_cm - one.mean_error_cm) < 1e-6
    probe = GroundProbe(openbody, betas)
    for a, b in zip(probe.lowest(one.rotations, one.transl, window=100),
                    probe.lowest(one.rotations, one.transl, window=10**6)):
        np.testing.assert_array_equal(a, b)
    with torch.no_grad():
        mesh = openbody.forward(torch.as_tensor(betas)[None], torch.as_tensor(one.rotations[:300]),
                                torch.as_tensor(one.transl[:300])).joints
        fk = posed_joints(openbody, betas, one.rotations[:300], one.transl[:300], window=64)
    np.testing.assert_allclose(fk.numpy(), mesh.numpy(), atol=1e-6)


def test_windowed_encoder_gives_the_same_tokens(joints, openbody):
    """The shipped SA-VAE encodes the take window by window with its receptive field on both
    sides (``encoder_reach``; the residual encoder has the same layers): every token, base and
    residual, equals the one-pass token."""
    from shapemove.core.generation.retarget import encode_windowed, encoder_reach, load_vae, processor

    vae = load_vae(None, openbody)
    reach = encoder_reach(vae)
    assert reach % vae.cfg.downsample == 0 and reach >= 40
    feats = processor(openbody, 2).process(joints[:1201])["norm_joint_vecs"]
    x = vae.normalize(torch.as_tensor(feats[:1200], dtype=torch.float32))
    with torch.no_grad():
        whole = vae.encode_tokens(x[None])[0]   # base and residual codes (the shipped codec has both)
    win = encode_windowed(vae, x, window=128)  # 9 windows, each with `reach` frames of context
    assert len(win) == 300 and torch.equal(win, whole)
    assert len(set(whole.tolist())) > 20 and bool((whole >= 1000).all())  # a real walk's many codes, residuals packed in


def _retarget_peak_mb(path, out) -> float:
    r = subprocess.run([sys.executable, "-c", RUN_WITH_PEAK, "retarget", "--motion", str(path), "--betas", "1.5",
                        "--naive", "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    return int(r.stderr.split("PEAK_KB")[-1].split()[0]) / 1024


def test_retarget_memory_does_not_grow_with_the_take(takes, tmp_path):
    """The whole CLI (read, IK, grounding, write) on 30 s and on 90 s of the same walk: the 90 s take
    costs at most 100 MB more (it cost ~2 GB more before) and stays under 1 GB in all."""
    short = _retarget_peak_mb(takes[30], tmp_path / "short.npz")
    long = _retarget_peak_mb(takes[90], tmp_path / "long.npz")
    assert long < 1024, (short, long)
    assert long - short < 100, (short, long)
    from shapemove.core.scene.motion_file import load_motion

    m = load_motion(tmp_path / "long.npz")
    assert 1795 <= m.num_frames <= 1801 and np.isfinite(m.joints).all()
