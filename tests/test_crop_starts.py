"""Crop starts where the body moves (train.active_windows) and batches cut on the device
(train.resident): the draws they make, checked against what they are for."""
from __future__ import annotations

import numpy as np
import torch

from shapemove.core.motion.features import feature_slices
from shapemove.core.train.crop_starts import pose_motion, start_weights


def _clip(frames: int, moving: slice) -> np.ndarray:
    """(frames, 263) features whose root-relative joints stand still except in ``moving``, where
    one joint sways 2 cm a frame."""
    f = np.zeros((frames, 263), np.float32)
    ric = f[:, feature_slices["ric"]].reshape(frames, 21, 3)
    ric[moving, 5, 0] = 0.02 * (np.arange(moving.stop - moving.start) % 2)
    f[:, feature_slices["ric"]] = ric.reshape(frames, -1)
    return f


def test_pose_motion_is_the_joints_summed_step():
    f = _clip(10, slice(4, 8))
    m = pose_motion(f)
    assert m.shape == (10,)
    assert np.allclose(m[:3], 0) and np.allclose(m[4:7], 0.02) and m[-1] == m[-2]


def test_start_weights_favour_the_crops_where_the_pose_moves():
    f = _clip(200, slice(150, 190))          # a long still start, then 2 s of movement
    uniform = start_weights(f, 32, 0.0)
    assert uniform.shape == (169,) and np.allclose(uniform, 1)
    w = start_weights(f, 32, 1.0)
    assert abs(w.mean() - 1) < 1e-9
    p = w / w.sum()
    # crops that hold some of the movement start at 119..168: half the weight or more goes there
    share = p[119:].sum()
    assert share > 0.9                        # uniform would give 50 / 169 = 0.30
    half = start_weights(f, 32, 0.5) / start_weights(f, 32, 0.5).sum()
    assert 0.3 < half[119:].sum() < share     # the mix sits between
    assert (w > 0).all()                      # a still crop stays possible (FLOOR)


def test_resident_batches_cut_the_crops_the_weights_ask_for(tmp_path):
    from shapemove.core.train.motion_dataset import MotionClips
    from shapemove.core.train.resident_batches import ResidentBatches

    rng = np.random.default_rng(0)
    lengths = {"a": 40, "b": 100, "c": 70}
    for sub in ("norm_joint_vecs", "new_joint_vecs", "betas", "contacts"):
        (tmp_path / sub).mkdir()
    for i, (cid, n) in enumerate(lengths.items()):
        x = rng.normal(size=(n, 263)).astype(np.float32)
        x[:, 0] = i                                       # channel 0 names the clip
        x[:, 1] = np.arange(n)                            # channel 1 the frame
        np.save(tmp_path / "norm_joint_vecs" / f"{cid}.npy", x)
        np.save(tmp_path / "new_joint_vecs" / f"{cid}.npy", x * 2)
        np.save(tmp_path / "betas" / f"{cid}.npy", np.full(10, i, np.float32))
        np.save(tmp_path / "contacts" / f"{cid}.npy", np.zeros((n, 4), np.uint8))
    np.save(tmp_path / "Mean.npy", np.zeros(263, np.float32))
    np.save(tmp_path / "Std.npy", np.ones(263, np.float32))
    (tmp_path / "train.txt").write_text("a\nb\nc\n")
    ds = MotionClips(tmp_path, "train", window=16)
    rb = ResidentBatches(ds, batch=64, seed=1, weights=[0.0, 1.0, 3.0])
    seen = {0: 0, 1: 0, 2: 0}
    it = iter(rb)
    for _ in range(20):
        b = next(it)
        clip = b["x"][:, 0, 0].long()
        for k in range(3):
            seen[k] += int((clip == k).sum())
        assert torch.equal(b["y"], b["x"] * 2)                                   # the same frames
        assert torch.equal(b["betas"][:, 0].long(), clip)                        # the clip's own body
        steps = b["x"][:, 1:, 1] - b["x"][:, :-1, 1]
        assert torch.all(steps == 1)                                             # consecutive frames
        n = torch.tensor([lengths[k] for k in "abc"])[clip]
        assert torch.all(b["x"][:, -1, 1] <= n - 1)                              # inside the clip
    assert seen[0] == 0 and 2.5 < seen[2] / seen[1] < 3.5                        # the weights
    again = next(iter(ResidentBatches(ds, batch=64, seed=1, weights=[0.0, 1.0, 3.0], start_step=5)))
    fifth = [next(x) for x in [iter(rb)] for _ in range(6)][-1]
    assert torch.equal(again["x"], fifth["x"])                                   # a function of the step
    # crop starts drawn by movement: still consecutive frames inside the clip, and the moving part favoured
    x = np.load(tmp_path / "norm_joint_vecs" / "b.npy")
    x[:, feature_slices["ric"]] = 0
    x[80:, feature_slices["ric"]] = rng.normal(size=(20, 63))                    # only the last 20 frames move
    np.save(tmp_path / "norm_joint_vecs" / "b.npy", x)
    np.save(tmp_path / "new_joint_vecs" / "b.npy", x * 2)
    active = ResidentBatches(MotionClips(tmp_path, "train", window=16, active_windows=1.0), batch=256, seed=2,
                             weights=[0.0, 1.0, 0.0])
    b = next(iter(active))
    first = b["x"][:, 0, 1]
    assert torch.all(b["x"][:, 1:, 1] - b["x"][:, :-1, 1] == 1) and torch.all(first <= 100 - 16)
    assert float((first >= 65).float().mean()) > 0.8                             # crops reaching frame 80+


def test_a_time_budget_fits_the_step_count():
    from shapemove.core.models.savae import TrainSettings
    from shapemove.core.train.train_vae import fitted_steps

    t = TrainSettings(steps=100_000)
    # 60 s gone at step 200, 0.01 s a step, 5 minutes: 0.95 * 300 - 60 = 225 s left -> 22,500 steps more
    assert fitted_steps(200, 60.0, 0.01, 5.0, t) == 22_700
    assert fitted_steps(200, 400.0, 0.01, 5.0, t) == 201          # over budget: stop at once
    assert fitted_steps(200, 1.0, 1e-6, 5.0, t) == 100_000        # never past the config's ceiling


def test_a_clip_shorter_than_the_window_is_trained_whole_and_its_padding_counts_in_no_loss(tmp_path):
    """Kicks, squats and reaches up are 26-60 frame takes: with a 64-frame window they were left
    out of the codec's training (38 % of the training split). With ``min_frames`` a shorter clip is
    served whole from its first frame, zeros after, ``valid`` marking its frames, the same on the
    CPU and resident paths; and every loss of a padded item equals the loss of the clip alone."""
    from shapemove.core.models.savae import LossWeights
    from shapemove.core.models.vae_losses import vae_losses
    from shapemove.core.train.motion_dataset import MotionClips
    from shapemove.core.train.resident_batches import ResidentBatches

    rng = np.random.default_rng(3)
    for sub in ("norm_joint_vecs", "new_joint_vecs", "betas", "contacts"):
        (tmp_path / sub).mkdir()
    for i, (cid, n) in enumerate({"kick": 26, "walk": 80, "tiny": 8}.items()):
        x = rng.normal(size=(n, 263)).astype(np.float32) * 0.1
        x[:, 0] = i + 1
        np.save(tmp_path / "norm_joint_vecs" / f"{cid}.npy", x)
        np.save(tmp_path / "new_joint_vecs" / f"{cid}.npy", x * 2)
        np.save(tmp_path / "betas" / f"{cid}.npy", np.zeros(10, np.float32))
        np.save(tmp_path / "contacts" / f"{cid}.npy", (rng.random((n + 1, 4)) > 0.5).astype(np.uint8))   # as built:
        # a row a frame, the features one fewer
    np.save(tmp_path / "Mean.npy", np.zeros(263, np.float32))
    np.save(tmp_path / "Std.npy", np.ones(263, np.float32))
    (tmp_path / "train.txt").write_text("kick\nwalk\ntiny\n")

    assert MotionClips(tmp_path, "train", window=32).ids == ["walk"]                # no min_frames: as before
    ds = MotionClips(tmp_path, "train", window=32, min_frames=16)
    assert ds.ids == ["kick", "walk"] and ds.skipped == ["tiny"]
    item = ds[(0, 0)]
    assert torch.equal(item["valid"], (torch.arange(32) < 26).float())
    assert torch.all(item["x"][:26, 0] == 1) and torch.all(item["x"][26:] == 0) and torch.all(item["contacts"][26:] == 0)
    assert ds[(1, 0)]["valid"].sum() == 32
    rb = next(iter(ResidentBatches(ds, batch=64, seed=0, weights=[1.0, 0.0])))    # the kick alone
    assert torch.equal(rb["x"][0], item["x"]) and torch.equal(rb["valid"][0], item["valid"])
    assert torch.equal(rb["contacts"][0], item["contacts"])
    walk = np.load(tmp_path / "contacts" / "walk.npy")[:, [0, 2, 1, 3]]
    rw = next(iter(ResidentBatches(ds, batch=64, seed=0, weights=[0.0, 1.0])))     # the walk's contacts are
    start = int(np.flatnonzero((np.load(tmp_path / "norm_joint_vecs" / "walk.npy") == rw["x"][0, 0].numpy()).all(1))[0])
    assert np.array_equal(rw["contacts"][0].numpy(), walk[start:start + 32])        # its own, after the kick's

    weights = LossWeights(recon_mse=0.5, floating=0.1, slide=0.5, root=1.0, bone=1.0)
    pred = item["y"] + torch.as_tensor(rng.normal(size=(32, 263)).astype(np.float32)) * 0.05
    mean, std = torch.zeros(263), torch.ones(263)
    padded = vae_losses(pred[None], item["y"][None], mean, std, weights, contacts=item["contacts"][None],
                        valid=item["valid"][None], target_bones=torch.full((1, 21), 0.3))
    alone = vae_losses(pred[None, :26], item["y"][None, :26], mean, std, weights, contacts=item["contacts"][None, :26],
                       target_bones=torch.full((1, 21), 0.3))
    for name in alone:
        assert torch.allclose(padded[name], alone[name], rtol=1e-4, atol=1e-6), name
    garbage = pred.clone()
    garbage[26:] = 50.0                                                             # what the padding decodes to
    again = vae_losses(garbage[None], item["y"][None], mean, std, weights, contacts=item["contacts"][None],
                       valid=item["valid"][None], target_bones=torch.full((1, 21), 0.3))
    assert torch.allclose(again["total"], padded["total"], rtol=1e-4)
