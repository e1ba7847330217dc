"""SA-VAE model: shapes, shape injection, long decoding, config, and the training losses."""
import json
import math

import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.models.savae import SAVAE, SAVAEConfig, TrainSettings
from shapemove.core.models import vae_losses as L

CLIP = "bandai/dataset-1/data/dataset-1_walk-back_active_001.bvh"


def tiny(**kw) -> SAVAEConfig:
    return SAVAEConfig(**{"width": 16, "depth": 2, "shape_hidden": 16, **kw})


def test_shapes_small_and_paper():
    torch.manual_seed(0)
    for cfg in (tiny(), SAVAEConfig.paper()):
        m = SAVAE(cfg)
        out = m(torch.randn(2, 64, 263), torch.randn(2, 10))
        assert out["codes"].shape == (2, 16, 4) and out["indices"].shape == (2, 16)
        assert out["recon"].shape == (2, 64, 263)
        assert int(out["indices"].max()) < 1000
    paper = SAVAEConfig.paper()
    assert (paper.width, paper.depth, paper.dilation_growth, paper.downsample, paper.levels) == (512, 3, 3, 4, (8, 5, 5, 5))
    with pytest.raises(ShapeMoveError, match="multiple of 4"):
        SAVAE(tiny()).encode(torch.randn(1, 62, 263))
    with pytest.raises(ShapeMoveError, match="betas"):
        SAVAE(tiny()).decode(torch.zeros(1, 16, 4), torch.zeros(1, 9))


@pytest.mark.parametrize("token_dim", [0, 4])  # decoder-width token (default) and raw code-width token
def test_decoder_depends_on_betas_everywhere(token_dim):
    """With the paper's dilations (depth 3, growth 3) the prepended token reaches all 64 frames."""
    torch.manual_seed(0)
    m = SAVAE(tiny(shape_token_dim=token_dim, depth=3)).eval()
    codes = m.quantizer.indices_to_codes(torch.randint(0, 1000, (1, 16)))
    b0, b1 = torch.zeros(1, 10), torch.zeros(1, 10)
    b1[0, 0] = 2.0
    with torch.no_grad():
        y0, y0b, y1 = m.decode(codes, b0), m.decode(codes, b0.clone()), m.decode(codes, b1)
    assert torch.equal(y0, y0b)
    per_frame = (y1 - y0).abs().amax(-1)[0]                      # (64,)
    assert (per_frame > 0).all(), "every frame, up to the last, must see the shape token"


def test_decode_long_matches_decode():
    torch.manual_seed(0)
    m = SAVAE(tiny()).eval()
    betas = torch.randn(2, 10)
    short = m.quantizer.indices_to_codes(torch.randint(0, 1000, (2, 12)))
    assert torch.equal(m.decode_long(short, betas), m.decode(short, betas))
    codes = m.quantizer.indices_to_codes(torch.randint(0, 1000, (2, 40)))
    y = m.decode_long(codes, betas, chunk=16, overlap=4)
    assert y.shape == (2, 160, 263) and torch.isfinite(y).all()
    with torch.no_grad():  # frames covered by the first chunk only are its own decoding
        first = m.decode(codes[:, :16], betas)[:, : (16 - 4) * 4]
        last = m.decode(codes[:, -16:], betas)[:, -(16 - 4) * 4:]
    assert torch.allclose(y[:, :48], first, atol=1e-6) and torch.allclose(y[:, -48:], last, atol=1e-6)


def test_stats_buffers_normalize():
    mean, std = torch.randn(263), torch.rand(263) + 0.5
    m = SAVAE(tiny(), mean, std)
    f = torch.randn(3, 263)
    assert torch.allclose(m.denormalize(m.normalize(f)), f, atol=1e-5)
    assert torch.equal(m.state_dict()["mean"], mean)
    with pytest.raises(ShapeMoveError):
        m.set_stats(torch.zeros(10), torch.ones(10))


def test_config_json(tmp_path):
    cfg = SAVAEConfig.small()
    assert SAVAEConfig.from_dict(cfg.to_dict()) == cfg
    p = tmp_path / "c.json"
    p.write_text(json.dumps({"base": "small", "width": 64, "loss": {"bone": 2.0}, "train": {"milestones": [0.5]}}))
    c = SAVAEConfig.load(str(p))
    assert (c.width, c.depth, c.loss.bone, c.train.milestones, c.train.batch_size) == (64, 3, 2.0, (0.5,), 32)
    for bad in ({"widht": 3}, {"loss": {"nope": 1}}, {"loss": {"dyn_stability": -1.0}}, {"base": "huge"}):
        p.write_text(json.dumps(bad))
        with pytest.raises(ShapeMoveError):
            SAVAEConfig.load(str(p))
    with pytest.raises(ShapeMoveError, match="not found"):
        SAVAEConfig.load(str(tmp_path / "missing.json"))
    with pytest.raises(ShapeMoveError, match="window"):
        SAVAE(SAVAEConfig(train=TrainSettings(window=62)))


# -- losses on constructed cases --------------------------------------------------------------------

@pytest.fixture(scope="module")
def clip(mocap_root):
    """A real walk: joints (T,22,3) as recovered from its features, and the features."""
    from shapemove.core.io.mocap import load_smpl22
    from shapemove.core.motion.features import features_from_joints, joints_from_features

    feats = torch.as_tensor(features_from_joints(load_smpl22(mocap_root / CLIP).joints))
    return joints_from_features(feats), feats


def rigid_motion(j0: torch.Tensor, T: int = 30) -> torch.Tensor:
    """A skeleton frame turned about Y and translated over T frames: bones exactly constant."""
    ang = torch.linspace(0, 1.5, T)
    c, s = torch.cos(ang), torch.sin(ang)
    R = torch.zeros(T, 3, 3)
    R[:, 0, 0], R[:, 0, 2], R[:, 1, 1], R[:, 2, 0], R[:, 2, 2] = c, s, 1, -s, c
    move = torch.stack([torch.linspace(0, 2, T), torch.zeros(T), torch.linspace(0, -1, T)], -1)
    return torch.einsum("tij,kj->tki", R, j0) + move[:, None]


def test_bone_length_loss_rigid_motion(clip):
    joints, _ = clip
    j0 = joints[0]
    motion = rigid_motion(j0)[None]                              # (1,T,22,3)
    own = L.bone_lengths(j0)[None]
    assert L.bone_length_loss(motion, own) < 1e-6
    # against a body whose bones are all 10% longer the loss is 10% of the mean bone length
    assert L.bone_length_loss(motion, own * 1.1) == pytest.approx(0.1 * float(own.mean()), rel=1e-4)


def test_penetration_floating_sliding(clip):
    joints, _ = clip
    J = joints[None]                                             # floor at y = 0
    assert L.penetration_loss(J) == 0
    sunk = J - torch.tensor([0, 0.1, 0])
    assert L.penetration_loss(sunk) == pytest.approx(float(torch.relu(0.1 - J[..., 1]).mean()), rel=1e-5)
    assert L.penetration_loss(sunk) > 0.005
    T = J.shape[1]
    contacts = torch.ones(1, T, 4)
    assert L.floating_loss(J, J, contacts) == 0
    assert L.floating_loss(J + torch.tensor([0, 0.07, 0]), J, contacts) == pytest.approx(0.07, abs=1e-6)
    assert L.floating_loss(J + torch.tensor([0, 0.07, 0]), J, torch.zeros(1, T, 4)) == 0   # no contact: free
    still = J[:, :1].expand(1, T, 22, 3)
    slide = still + torch.arange(T)[None, :, None, None] * torch.tensor([0.03, 0, 0.04])   # 5 cm per frame
    assert L.foot_slide_loss(still, contacts) == 0
    assert L.foot_slide_loss(slide, contacts) == pytest.approx(0.05, rel=1e-5)
    assert L.foot_slide_loss(slide, torch.zeros(1, T, 4)) == 0


def test_squared_reconstruction_counts_a_far_pose_in_full():
    """``recon_mse``: the mean squared error of the normalized features, off unless weighted. One
    feature 4 std off in one of 4 x 263 values: squared 16 / 1052, where smooth L1 gives (4 - 0.5) /
    1052, so the far pose weighs 4.6x more against the same error spread thin (0.1 everywhere:
    0.01 squared against 0.005)."""
    target = torch.zeros(1, 4, 263)
    far = target.clone()
    far[0, 2, 7] = 4.0
    thin = target + 0.1
    w = SAVAEConfig().loss
    assert w.recon_mse == 0 and "recon_mse" not in L.vae_losses(far, target, torch.zeros(263), torch.ones(263), w)
    w.recon_mse, w.recon = 1.0, 0.0
    out = L.vae_losses(far, target, torch.zeros(263), torch.ones(263), w)
    assert float(out["recon_mse"]) == pytest.approx(16 / 1052, rel=1e-6)
    assert float(out["recon"]) == pytest.approx(3.5 / 1052, rel=1e-6)
    assert float(L.vae_losses(thin, target, torch.zeros(263), torch.ones(263), w)["recon_mse"]) == pytest.approx(0.01, rel=1e-4)
    assert float(out["total"]) == pytest.approx(sum(getattr(w, k) * float(v) for k, v in out.items() if k != "total"), rel=1e-6)


def test_vae_losses_through_features(clip):
    """End to end on features: a prediction equal to the target has zero reconstruction losses,
    the same motion sunk 10 cm (root height and ric heights lowered) penetrates."""
    _, feats = clip
    f = feats[None, :64]
    mean, std = f.mean(1)[0], f.std(1)[0] + 0.1
    target = (f - mean) / std
    w = SAVAEConfig().loss
    same = L.vae_losses(target, target, mean, std, w)
    assert same["recon"] == 0 and same["vel"] == 0 and same["penetrate"] == 0 and same["floating"] == 0
    sunk = f.clone()
    sunk[..., 3] -= 0.1
    sunk[..., 5:67:3] -= 0.1                                     # y of the 21 ric joints
    pred = ((sunk - mean) / std).requires_grad_()
    out = L.vae_losses(pred, target, mean, std, w)
    v = {k: float(x.detach()) for k, x in out.items()}
    assert v["penetrate"] > 0.005 and v["recon"] > 0
    assert v["bone"] == pytest.approx(float(same["bone"]), abs=1e-5)   # sinking keeps bone lengths
    expected = sum(getattr(w, k) * v[k] for k in ("recon", "vel", "bone", "floating", "slide", "penetrate"))
    assert v["total"] == pytest.approx(expected, rel=1e-6)
    out["total"].backward()
    assert torch.isfinite(pred.grad).all() and pred.grad.abs().sum() > 0
    assert not math.isnan(v["slide"])
