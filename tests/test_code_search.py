"""Encoding by search (core/models/code_search.py): the codes whose decoding comes closest to a take,
on a real walk (tiny_dataset) with the shipped SA-VAE, measured with the evaluation's own MPJPE and
bone error (core/eval/bones.py), not with the search's loss."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.motion.features import joints_from_features

pytestmark = pytest.mark.usefixtures("one_thread")
WALK = "dataset-1_walk_feminine_001"
SAVAE = Path(__file__).resolve().parents[1] / "weights" / "default" / "savae.pt"


@pytest.fixture(scope="module")
def codec(openbody):
    if not SAVAE.is_file():
        pytest.skip(f"{SAVAE} missing")
    from shapemove.core.generation.retarget import load_vae

    return load_vae(SAVAE, openbody)


@pytest.fixture(scope="module")
def walk(tiny_dataset):
    load = lambda sub: np.load(tiny_dataset / sub / f"{WALK}.npy")  # noqa: E731
    return {"norm": load("norm_joint_vecs"), "shaped": load("new_joint_vecs"), "betas": load("betas").reshape(-1)}


def _decoded(codec, tokens, betas):
    with torch.no_grad():
        f = codec.decode_tokens_long(torch.as_tensor(tokens)[None], torch.as_tensor(betas, dtype=torch.float32)[None])
    return joints_from_features(codec.denormalize(f)[0].double()).numpy()


def test_loss_of_hand_made_motions():
    """Hand-derived values: a whole body moved by d has no root-aligned or bone error, only the
    trajectory's |d|; one bone 3 cm longer in every frame is 3 cm / 21 of bone error and moves one
    joint 3 cm in the root's frame (1/22 of the joints); a root drifting 1 m over 2 s (0.5 m/s)
    more than the target's has a 1 s travel error of 0.5 m/s."""
    from shapemove.core.models.code_search import joint_loss

    g = torch.Generator().manual_seed(0)
    target = torch.randn(50, 22, 3, generator=g) * 0.3
    d = torch.tensor([0.3, 0.0, 0.4])                                        # |d| = 0.5 m
    shifted = target + d
    assert float(joint_loss(shifted, target, 0.1, 4.0, 0.0)) == pytest.approx(0.1 * 0.5, abs=1e-5)
    assert float(joint_loss(shifted, target, 0.0, 4.0, 1.0)) == pytest.approx(0.0, abs=1e-5)
    longer = target.clone()
    bone = target[:, 15] - target[:, 12]                                     # neck -> head
    longer[:, 15] = target[:, 12] + bone * (1 + 0.03 / bone.norm(dim=-1, keepdim=True))
    assert float(joint_loss(longer, target, 0.0, 1.0, 0.0)) == pytest.approx(0.03 / 22 + 0.03 / 21, abs=1e-5)
    drift = target.clone()
    t = torch.arange(50, dtype=torch.float32)[:, None] / 20.0                # 20 fps: 2.45 s
    drift[..., 0] += 0.5 * t                                                 # every joint, so no pose error
    loss = float(joint_loss(drift, target, 0.0, 0.0, 1.0))
    assert loss == pytest.approx(0.5, abs=1e-4)


def test_search_brings_a_real_walk_closer_than_the_encoders(codec, walk, openbody):
    """The shipped codec on a real Bandai walk, decoded on its own body: the searched codes give a
    smaller root-aligned MPJPE (40.9 -> 37.6 mm when written), a far smaller MPJPE with the root's
    path (65 -> 43 mm) and a smaller bone error (4.50 -> 3.21 mm) than the encoders' codes; the
    search is deterministic."""
    from shapemove.core.eval.bones import bone_length_error_mm, mpjpe_mm, target_bone_lengths
    from shapemove.core.generation.retarget import encode_take

    plain = encode_take(codec, walk["norm"], walk["betas"], walk["shaped"], search=False)
    searched = encode_take(codec, walk["norm"], walk["betas"], walk["shaped"])
    assert len(searched) == len(plain) == len(walk["norm"]) // 4
    assert min(searched) >= 1000                                   # both codes, packed (motion_codes)
    a, b = _decoded(codec, plain, walk["betas"]), _decoded(codec, searched, walk["betas"])
    gt = joints_from_features(walk["shaped"][:len(a)].astype(np.float64))
    assert mpjpe_mm(b, gt, root_aligned=True) < 0.95 * mpjpe_mm(a, gt, root_aligned=True)
    assert mpjpe_mm(b, gt) < 0.75 * mpjpe_mm(a, gt)
    bones = target_bone_lengths(openbody, torch.as_tensor(walk["betas"])[None])
    assert bone_length_error_mm(b, bones) < 0.85 * bone_length_error_mm(a, bones)
    assert encode_take(codec, walk["norm"], walk["betas"], walk["shaped"]) == searched


def test_no_steps_keeps_the_encoders_codes_and_a_step_never_scores_worse(codec, walk):
    from shapemove.core.generation.retarget import encode_latents, encode_windowed
    from shapemove.core.models.code_search import joint_loss, search_tokens

    n = len(walk["norm"]) // 4 * 4
    x = codec.normalize(torch.as_tensor(walk["norm"][:n], dtype=torch.float32))
    target = torch.as_tensor(joints_from_features(walk["shaped"][:n].astype(np.float64)), dtype=torch.float32)
    latents = encode_latents(codec, x)
    plain = encode_windowed(codec, x)
    assert torch.equal(search_tokens(codec, latents, walk["betas"], walk["shaped"][:n], steps=0), plain)

    def loss(tokens):
        return float(joint_loss(torch.as_tensor(_decoded(codec, tokens, walk["betas"]), dtype=torch.float32), target))

    assert loss(search_tokens(codec, latents, walk["betas"], walk["shaped"][:n], steps=3)) <= loss(plain)


def test_a_long_take_is_searched_window_by_window(codec, walk):
    """Windows of 12 tokens (fixed context around each): the same number of tokens, codes moved
    in every window, and closer to the take than the encoders' codes by the same loss measured
    over the whole take."""
    from shapemove.core.generation.retarget import encode_latents, encode_windowed
    from shapemove.core.models.code_search import joint_loss, search_tokens

    n = len(walk["norm"]) // 4 * 4
    x = codec.normalize(torch.as_tensor(walk["norm"][:n], dtype=torch.float32))
    target = torch.as_tensor(joints_from_features(walk["shaped"][:n].astype(np.float64)), dtype=torch.float32)
    seen = []
    win = search_tokens(codec, encode_latents(codec, x), walk["betas"], walk["shaped"][:n], steps=15, window=12,
                        progress=seen.append)
    windows = -(-(n // 4) // 12)
    assert len(win) == n // 4 and seen[-1] == 1.0 and seen == sorted(seen)
    assert len(seen) == windows * (1 + 15 // 10 + 1)     # every 10 steps (0 and 10 of 15) and each window's end
    plain = encode_windowed(codec, x)
    def loss(tokens):
        return float(joint_loss(torch.as_tensor(_decoded(codec, tokens, walk["betas"]), dtype=torch.float32), target))

    assert loss(win) < 0.97 * loss(plain)
    assert (win != plain).sum() > len(win) // 4               # every window moved codes, not only the first


def test_search_refuses_bad_input(codec, walk):
    from shapemove.core.generation.retarget import encode_latents, encode_take
    from shapemove.core.models.code_search import search_tokens

    x = codec.normalize(torch.as_tensor(walk["norm"][:40], dtype=torch.float32))
    latents = encode_latents(codec, x)
    with pytest.raises(ShapeMoveError, match="target features must be"):
        search_tokens(codec, latents, walk["betas"], walk["shaped"][:39])
    with pytest.raises(ShapeMoveError, match="residual latents"):
        search_tokens(codec, (latents[0], None), walk["betas"], walk["shaped"][:40])
    with pytest.raises(ShapeMoveError, match="steps must be"):
        search_tokens(codec, latents, walk["betas"], walk["shaped"][:40], steps=-1)
    with pytest.raises(ShapeMoveError, match="shape-aware feature rows"):
        encode_take(codec, walk["norm"][:40], walk["betas"], walk["shaped"][:20])
    with pytest.raises(ShapeMoveError, match="too short"):
        encode_take(codec, walk["norm"][:3], walk["betas"], walk["shaped"][:3])


def test_the_retarget_job_shows_the_search_and_cancels_during_it(mocap_root, tmp_path):
    """The panel's Retarget (the worker's ``retarget`` job) reports the search as progress and stops
    inside it when cancelled, writing nothing."""
    if not SAVAE.is_file():
        pytest.skip(f"{SAVAE} missing")
    from shapemove.core.worker import jobs_shapemove
    from shapemove.core.worker.op_support import JobCancelled

    seen = []
    out = tmp_path / "tall.npz"
    params = {"source": str(mocap_root / "bandai" / "dataset-1" / "data" / "dataset-1_run_happy_001.bvh"),
              "betas": [1.0] + [0.0] * 9, "method": "savae", "out": str(out)}
    with pytest.raises(JobCancelled):
        jobs_shapemove.retarget(params, lambda f, m: seen.append((f, m)),
                                lambda: any("searching codes" in m for _, m in seen))
    assert [m for _, m in seen if "searching codes" in m] and not out.exists()
    assert all(0.3 <= f <= 0.9 for f, m in seen if "searching codes" in m)


def test_the_retarget_job_keeps_a_kick_the_codec_flattens(mocap_root, tmp_path):
    """The panel's Retarget ("auto") checks the searched codes on the subject's own body first. A
    captured front kick (the right foot 1.0 m above its lowest point) comes back from the shipped
    codec at under 0.4 m: auto moves the take by its own rotations instead, feet planted, and says
    why; a walk stays on the SA-VAE (tokens, no note). "savae" keeps the codec's motion anyway."""
    if not SAVAE.is_file():
        pytest.skip(f"{SAVAE} missing")
    from shapemove.core.body.load import load_body_model
    from shapemove.core.generation.retarget import source_joints
    from shapemove.core.scene.motion_file import load_motion
    from shapemove.core.worker import jobs_shapemove

    data = mocap_root / "bandai" / "dataset-1" / "data"
    kick = data / "dataset-1_kick_normal_001.bvh"

    def job(source, method):
        out = tmp_path / f"{source.stem}_{method}.npz"
        r = jobs_shapemove.retarget({"source": str(source), "betas": [1.0] + [0.0] * 9, "method": method,
                                     "out": str(out)}, lambda f, m: None, lambda: False)
        return r, load_motion(out)

    src = source_joints(kick, load_body_model(None))[0][:, 8, 1]
    lift = lambda y: float(y.max() - y.min())  # noqa: E731   (the right ankle's rise)
    assert lift(src) > 0.9
    r, m = job(kick, "auto")
    assert r["method"] == "planted" and r["tokens"] == 0 and m.tokens is None and len(src) == m.num_frames
    assert len(r["notes"]) == 1 and "worst second" in r["notes"][0]
    assert lift(m.joints[:, 8, 1]) > 0.95 * lift(src)        # the kick is kept (on a taller body)
    r, m = job(kick, "savae")
    assert r["method"] == "savae" and not r["notes"] and lift(m.joints[:, 8, 1]) < 0.5 * lift(src)
    r, m = job(data / f"{WALK}.bvh", "auto")
    assert r["method"] == "savae" and r["tokens"] == len(m.tokens) > 0 and not r["notes"]
