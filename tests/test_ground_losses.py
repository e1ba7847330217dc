"""SA-VAE ground losses on the soles (sole offsets of the target body) and HUMOS's dynamic-stability
term (ZMP outside the contact feet)."""
import pytest
import torch

from shapemove.core.body.soles import sole_offsets
from shapemove.core.models import vae_losses as L
from shapemove.core.models.savae import SAVAEConfig


def _standing(openbody, T=12):
    """(1,T,22,3) rest pose standing with its soles on the floor, and its (1,4) sole offsets."""
    j = openbody.rest_joints(None)[0, :22]
    off = sole_offsets(openbody, None)
    return j[None, None].expand(1, T, 22, 3).clone(), off


def test_floating_and_penetration_act_on_the_soles(openbody):
    J, off = _standing(openbody)
    T = J.shape[1]
    on = torch.ones(1, T, 4)
    h = L.sole_heights(J, off)
    assert h.abs().max() < 2e-3                                   # rest pose: soles at y = 0
    assert L.floating_loss(J, J, on, off) < 2e-3
    up = J + torch.tensor([0, 0.03, 0])
    assert L.floating_loss(up, J, on, off) == pytest.approx(0.03 + float(h.mean()), abs=2e-3)
    assert L.floating_loss(up, J, torch.zeros(1, T, 4), off) == 0          # no contact: free to fly
    # the joint-based loss would not see a body sunk by its sole height; the sole-based one does
    sunk = J - torch.tensor([0, 0.025, 0])
    assert L.penetration_loss(sunk) < 1e-4
    depth = L.penetration_loss(sunk, off)
    assert depth == pytest.approx(4 * 0.025 / 22, rel=0.1)               # 4 contact joints of 22, 2.5 cm


def test_dynamic_stability_loss(openbody):
    J, _ = _standing(openbody, T=20)
    on = torch.ones(1, 20, 4)
    assert L.dynamic_stability_loss(J, on) == 0                        # static, CoM over the feet
    # a static lean: everything but the feet 50 cm in front of them
    lean = J.clone()
    body = [k for k in range(22) if k not in (7, 8, 10, 11)]
    lean[..., body, 2] += 0.50
    zmp = L.zero_moment_points(lean)
    feet_z = J[0, 0, [7, 8, 10, 11], 2].max()
    assert (zmp[0, :, 1] > feet_z + 0.1).all()
    loss = L.dynamic_stability_loss(lean, on)
    expected = float(zmp[0, 5, 1] - feet_z) - L.BOS_MARGIN
    assert loss == pytest.approx(expected, abs=0.02) and loss > 0.05
    assert L.dynamic_stability_loss(lean, torch.zeros(1, 20, 4)) == 0  # no contact: nothing to enforce
    # accelerating forward moves the ZMP backwards (behind the CoM): x_zmp = c - c_y a / g
    acc = J + (0.5 * 2.0 * (torch.arange(20) / 20.0) ** 2)[None, :, None, None] * torch.tensor([0, 0, 1.0])
    z = L.zero_moment_points(acc)[0, 5]
    com_z = float((acc[0, 5, :, 2] * L._MASS).sum() / L._MASS.sum())
    com_y = float((acc[0, 5, :, 1] * L._MASS).sum() / L._MASS.sum())
    assert float(z[1]) == pytest.approx(com_z - com_y * 2.0 / L.GRAVITY, abs=1e-3)


def test_vae_losses_with_soles_contacts_and_stability(openbody):
    from shapemove.core.motion.features import features_from_joints

    J, off = _standing(openbody, T=40)
    f = torch.as_tensor(features_from_joints(J[0].numpy(), keep_height=True))[None]
    mean, std = f.mean(1)[0], f.std(1)[0] + 0.1
    target = (f - mean) / std
    w = SAVAEConfig().loss
    w.dyn_stability = 1.0
    contacts = torch.ones(1, f.shape[1], 4)
    out = L.vae_losses(target, target, mean, std, w, sole_offsets=off, contacts=contacts)
    assert {"floating", "slide", "penetrate", "dyn_stability"} <= set(out)
    assert out["floating"] < 2e-3 and out["penetrate"] < 1e-3 and out["dyn_stability"] == 0
    sunk = f.clone()
    sunk[..., 3] -= 0.02
    sunk[..., 5:67:3] -= 0.02
    out = L.vae_losses((sunk - mean) / std, target, mean, std, w, sole_offsets=off, contacts=contacts)
    assert out["penetrate"] > 1e-3
    SAVAEConfig.from_dict({"loss": {"dyn_stability": 0.1}}).validate()
