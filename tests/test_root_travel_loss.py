"""The SA-VAE's root-travel term: a decoder that under-shoots the root's speed pays for the
distance it falls behind (hand-derived: 20 % slower -> 20 % of the target's mean distance)."""
import torch

from shapemove.core.models.vae_losses import root_travel_loss, vae_losses
from shapemove.core.models.savae import LossWeights
from shapemove.core.motion.features import feature_slices, joints_from_features


def _walk(speed: float, frames: int = 40) -> torch.Tensor:
    f = torch.zeros(1, frames, 263)
    f[..., feature_slices["root_lin_vel"].start + 1] = speed  # forward (z) m/frame, no turning
    f[..., feature_slices["root_y"]] = 0.9
    return f


def test_slower_root_pays_its_lag():
    target, slow = _walk(0.06), _walk(0.06 * 0.8)
    tj, sj = joints_from_features(target), joints_from_features(slow)
    dist = tj[..., 0, :][..., [0, 2]].norm(dim=-1).mean()
    assert dist > 0.5  # the target walks about a metre on average from its start
    track = root_travel_loss(sj, tj, torch.zeros_like(slow), torch.zeros_like(target))
    assert abs(float(track) - 0.2 * float(dist)) < 1e-4
    assert float(root_travel_loss(tj, tj, target, target)) == 0.0


def test_root_weight_enters_the_total():
    target, slow = _walk(0.06), _walk(0.05)
    mean, std = torch.zeros(263), torch.ones(263)
    off = vae_losses(slow, target, mean, std, LossWeights(root=0.0))
    on = vae_losses(slow, target, mean, std, LossWeights(root=1.0))
    assert "root" not in off and float(on["root"]) > 0.05
    assert abs(float(on["total"] - off["total"]) - float(on["root"])) < 1e-5
