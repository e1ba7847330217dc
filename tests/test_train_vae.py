"""SA-VAE training: dataset crops, schedule, checkpoints, exact resume, DDP under torchrun, CLI."""
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.models.savae import SAVAE, SAVAEConfig, TrainSettings, load_savae
from shapemove.core.train.checkpoint import load_checkpoint, make_metadata, save_checkpoint
from shapemove.core.train.motion_dataset import BatchStream, MotionClips
from shapemove.core.train.train_vae import lr_factor, train_vae

# Real Bandai clips of 83-138 frames at 20 fps: 3 for training (the first also retargeted onto a
# sampled body, as the builder's augmentation does), 1 for validation.
CLIPS = {"train": ["dataset-2_walk-turn-left_active_001", "dataset-2_walk-turn-left_active_002",
                   "dataset-1_walk-back_active_001"],
         "val": ["dataset-2_walk-turn-left_active_003"]}
AUG_BETAS = np.array([1.5, -1.0, 0.5, 0, 0, 0, 0, 0, 0, 0], np.float32)


def build_tiny_dataset(mocap_root: Path, out: Path) -> Path:
    """The dataset builder's per-clip pipeline (load, fit betas, IK, shape-aware and canonical FK,
    features; ``core/data/build.py``) on a few clips, with IK refinement off to stay fast."""
    from shapemove.core.data.build import ClipProcessor
    from shapemove.core.data.sources import discover, open_source
    from shapemove.core.motion.features import mean_std

    wanted = CLIPS["train"] + CLIPS["val"]
    clips = {c.id: c for c in discover(open_source(mocap_root / "bandai")) if c.id in wanted}
    proc = ClipProcessor(ik_refine_iters=0)
    for d in ("norm_joint_vecs", "new_joint_vecs", "betas"):
        (out / d).mkdir(parents=True)
    splits = {"train": [], "val": []}
    for split, ids in CLIPS.items():
        for cid in ids:
            joints = proc.load(clips[cid])
            todo = [(cid, None)] + ([(cid + "_aug", AUG_BETAS)] if cid == CLIPS["train"][0] else [])
            for name, betas in todo:
                arrays = proc.process(joints, betas)
                for key in ("norm_joint_vecs", "new_joint_vecs", "betas"):
                    np.save(out / key / f"{name}.npy", np.asarray(arrays[key], np.float32))
                splits[split].append(name)
    for split, ids in splits.items():
        (out / f"{split}.txt").write_text("\n".join(ids) + "\n")
    (out / "test.txt").write_text("")
    train = [np.load(out / k / f"{i}.npy") for i in splits["train"] for k in ("new_joint_vecs", "norm_joint_vecs")]
    mean, std = mean_std(train)
    np.save(out / "Mean.npy", mean)
    np.save(out / "Std.npy", std)
    return out


pytestmark = pytest.mark.usefixtures("one_thread")


@pytest.fixture(scope="module")
def data_dir(mocap_root, tmp_path_factory):
    return build_tiny_dataset(mocap_root, tmp_path_factory.mktemp("vae_data"))


@pytest.fixture(scope="module")
def body():
    from shapemove.core.body.load import load_body_model

    return load_body_model(None)


def tiny_config(**train) -> SAVAEConfig:
    settings = dict(steps=6, batch_size=4, warmup_steps=2, log_every=1, val_every=3, val_batches=1, ckpt_every=2)
    return SAVAEConfig(width=16, depth=1, shape_hidden=16, train=TrainSettings(**{**settings, **train}))


# -- data --------------------------------------------------------------------------------------------

def test_dataset_crops(data_dir):
    ds = MotionClips(data_dir, "train", window=64, seed=0)
    assert len(ds) == 4 and ds.skipped == []
    item = ds[(2, 5)]
    assert item["x"].shape == (64, 263) and item["y"].shape == (64, 263) and item["betas"].shape == (10,)
    assert torch.equal(ds[(2, 5)]["x"], item["x"])                     # deterministic per (index, epoch)
    raw = np.load(data_dir / "norm_joint_vecs" / f"{ds.ids[2]}.npy")
    x = item["x"].numpy() * ds.std + ds.mean                            # undo the normalization
    starts = [s for s in range(len(raw) - 63) if np.allclose(raw[s:s + 64], x, atol=1e-4)]
    assert len(starts) == 1                                             # a real 64-frame window of the clip
    starts_y = [s for s in range(len(raw) - 63)
                if np.allclose(np.load(data_dir / "new_joint_vecs" / f"{ds.ids[2]}.npy")[s:s + 64],
                               item["y"].numpy() * ds.std + ds.mean, atol=1e-4)]
    assert starts_y == starts                                           # same crop for input and target
    aug = ds[ds.ids.index(CLIPS["train"][0] + "_aug")]
    assert np.allclose(aug["betas"].numpy(), AUG_BETAS)
    assert (aug["x"] - aug["y"]).abs().max() > 0.1                      # shape-aware target differs from input
    assert len(MotionClips(data_dir, "train", window=100).skipped) >= 1  # 83-93 frame clips left out


def test_batch_stream_is_a_function_of_the_step(data_dir):
    ds = MotionClips(data_dir, "train", window=64)
    full = BatchStream(ds, batch=3, seed=7)
    it = iter(full)
    first = [next(it) for _ in range(6)]                                 # 18 items: crosses 4 epochs
    it2 = iter(BatchStream(ds, batch=3, seed=7, start_step=4))
    assert [next(it2) for _ in range(2)] == first[4:]
    for e in range(4):                                                  # each epoch is a permutation
        assert sorted(k[0] for b in first for k in b if k[1] == e) == [0, 1, 2, 3]
    r0 = next(iter(BatchStream(ds, 2, rank=0, world_size=2)))
    r1 = next(iter(BatchStream(ds, 2, rank=1, world_size=2)))
    assert sorted(k[0] for k in r0 + r1) == [0, 1, 2, 3]                # ranks split an epoch


def test_batch_stream_draws_by_weight_and_resumes(data_dir):
    """Action balance (``train.action_balance``): epochs drawn in proportion to the clips' weights,
    the same items from any start step, and a clip of weight 0 never drawn."""
    from shapemove.core.train.action_balance import clip_weights

    ds = MotionClips(data_dir, "train", window=64)
    w = [6.0, 2.0, 0.0, 0.0]
    it = iter(BatchStream(ds, batch=4, seed=3, weights=w))
    first = [next(it) for _ in range(500)]
    drawn = np.bincount([k[0] for b in first for k in b], minlength=4)
    assert drawn[2] == drawn[3] == 0 and drawn.sum() == 2000
    assert drawn[0] / drawn.sum() == pytest.approx(0.75, abs=0.03)     # 6 / (6 + 2)
    it2 = iter(BatchStream(ds, batch=4, seed=3, start_step=250, weights=w))
    assert [next(it2) for _ in range(3)] == first[250:253]
    with pytest.raises(ShapeMoveError, match="sampling weights"):
        BatchStream(ds, batch=4, weights=[0.0] * 4)
    with pytest.raises(ShapeMoveError, match="sampling weights"):
        BatchStream(ds, batch=4, weights=[1.0] * 3)
    # three walks and one sneak: balance 1 gives the sneak the walks' share together, 0 its clip's share
    labels = {"a": {"actions": ["walk"]}, "b": {"actions": ["walk"]}, "c": {"actions": ["walk"]},
              "d": {"actions": ["sneak"]}}
    assert clip_weights(list("abcd"), labels, 1.0).tolist() == pytest.approx([1 / 3] * 3 + [1.0])
    assert clip_weights(list("abcd"), labels, 0.0).tolist() == [1.0] * 4
    with pytest.raises(ShapeMoveError, match="action_balance"):
        SAVAEConfig.from_dict({"train": {"action_balance": 1.5}}).validate()


def test_lr_schedule():
    t = TrainSettings(warmup_steps=100, decay="step", milestones=(0.5, 0.8), gamma=0.1)
    assert lr_factor(0, t, 1000) == pytest.approx(0.01) and lr_factor(99, t, 1000) == 1.0
    assert lr_factor(499, t, 1000) == 1.0 and lr_factor(500, t, 1000) == pytest.approx(0.1)
    assert lr_factor(800, t, 1000) == pytest.approx(0.01)
    c = TrainSettings(warmup_steps=10, decay="cosine", min_lr_ratio=0.1)
    assert lr_factor(10, c, 110) == pytest.approx(1.0) and lr_factor(60, c, 110) == pytest.approx(0.55)
    assert lr_factor(110, c, 110) == pytest.approx(0.1)


# -- checkpoints ---------------------------------------------------------------------------------------

def test_checkpoint_round_trip_and_mismatches(tmp_path):
    cfg = tiny_config()
    m = SAVAE(cfg, torch.randn(263), torch.rand(263) + 0.5)
    meta = make_metadata("savae", cfg.to_dict(), "openbody-v1", m.mean, m.std, step=3)
    path = save_checkpoint(tmp_path / "savae.pt", {"model": m.state_dict()}, meta)
    assert not list(tmp_path.glob("*.tmp"))
    loaded = load_savae(path, body="openbody-v1")
    for k, v in m.state_dict().items():
        assert torch.equal(loaded.state_dict()[k], v)
    assert loaded.metadata["step"] == 3 and loaded.metadata["config"] == cfg.to_dict()
    with pytest.raises(ShapeMoveError, match="body model 'openbody-v1', not 'smplx'"):
        load_savae(path, body="smplx")
    other = cfg.to_dict()
    other["width"] = 32
    with pytest.raises(ShapeMoveError, match="width"):
        load_checkpoint(path, config=other)
    with pytest.raises(ShapeMoveError, match="normalization"):
        load_checkpoint(path, stats_hash_="0" * 64)
    with pytest.raises(ShapeMoveError, match="expected 't5'"):
        load_checkpoint(path, kind="t5")
    (tmp_path / "bad.pt").write_bytes(b"not a checkpoint")
    with pytest.raises(ShapeMoveError, match="cannot read"):
        load_checkpoint(tmp_path / "bad.pt")
    with pytest.raises(ShapeMoveError, match="not found"):
        load_checkpoint(tmp_path / "missing.pt")


# -- training -----------------------------------------------------------------------------------------

def test_resume_equals_uninterrupted(data_dir, body, tmp_path):
    full = train_vae(data_dir, tmp_path / "full", tiny_config(), body=body, device="cpu", verbose=False)
    assert full["step"] == 6 and "val" in full and np.isfinite(full["val"]["total"])
    calls = []

    def cancel_after_3():
        calls.append(1)
        return len(calls) > 3

    part = tmp_path / "part"
    assert train_vae(data_dir, part, tiny_config(), body=body, device="cpu", verbose=False,
                     cancel=cancel_after_3)["step"] == 3
    assert load_checkpoint(part / "last.pt")["step"] == 3 and not (part / "savae.pt").exists()
    progress = []
    train_vae(data_dir, part, tiny_config(), body=body, device="cpu", verbose=False, resume=True,
              progress=lambda f, msg: progress.append(f))
    assert progress[0] == pytest.approx(4 / 6) and progress[-1] == 1.0
    a = load_checkpoint(tmp_path / "full" / "last.pt")
    b = load_checkpoint(part / "last.pt")
    assert a["step"] == b["step"] == 6
    for k, v in a["model"].items():
        assert torch.equal(v, b["model"][k]), k
    for s_a, s_b in zip(a["optimizer"]["state"].values(), b["optimizer"]["state"].values()):
        assert torch.equal(s_a["exp_avg_sq"], s_b["exp_avg_sq"])
    assert a["scheduler"]["last_epoch"] == b["scheduler"]["last_epoch"] == 6
    model = load_savae(tmp_path / "full" / "savae.pt", body=body)
    assert model.metadata["body"] == body.name
    log = [json.loads(line) for line in (tmp_path / "full" / "log.jsonl").read_text().splitlines()]
    assert [r["step"] for r in log] == [1, 2, 3, 4, 5, 6] and "val" in log[2]
    # resuming with another architecture is refused
    with pytest.raises(ShapeMoveError, match="width"):
        train_vae(data_dir, part, SAVAEConfig(width=24, depth=1, shape_hidden=16, train=tiny_config().train),
                  body=body, device="cpu", verbose=False, resume=True, steps=8)


def test_training_reduces_loss(data_dir, body, tmp_path):
    cfg = tiny_config(steps=40, lr=1e-2, warmup_steps=1, log_every=1, val_every=40, ckpt_every=1000)
    train_vae(data_dir, tmp_path / "r", cfg, body=body, device="cpu", verbose=False)
    recon = [json.loads(line)["train"]["recon"] for line in (tmp_path / "r" / "log.jsonl").read_text().splitlines()]
    assert len(recon) == 40 and np.mean(recon[-5:]) < 0.9 * np.mean(recon[:5])


def test_decoder_fine_tune_keeps_every_token(data_dir, body, tmp_path):
    """Fine-tuning from a trained codec with the encoder and quantizer frozen: the encoder's weights,
    the normalization and so every clip's tokens stay exactly as they were, while the decoder and
    shape embedding learn (here the root-travel loss, off in the source run)."""
    train_vae(data_dir, tmp_path / "src", tiny_config(), body=body, device="cpu", verbose=False)
    src = load_savae(tmp_path / "src" / "savae.pt")
    # the fine-tune reads data with another normalization: the source's must win
    moved_stats = Path(shutil.copytree(data_dir, tmp_path / "data"))
    np.save(moved_stats / "Mean.npy", np.load(data_dir / "Mean.npy") + 0.5)
    cfg = tiny_config(steps=4, lr=1e-2, init_from=str(tmp_path / "src" / "savae.pt"), freeze=("encoder", "quantizer"))
    cfg.loss.root = 1.0
    train_vae(moved_stats, tmp_path / "ft", cfg, body=body, device="cpu", verbose=False)
    ft = load_savae(tmp_path / "ft" / "savae.pt")
    assert torch.equal(ft.mean, src.mean) and torch.equal(ft.std, src.std)
    for name, v in src.encoder.state_dict().items():
        assert torch.equal(v, ft.encoder.state_dict()[name]), name
    moved = [name for name, v in src.decoder.state_dict().items() if not torch.equal(v, ft.decoder.state_dict()[name])]
    assert moved and any(not torch.equal(v, ft.shape_embedding.state_dict()[k])
                         for k, v in src.shape_embedding.state_dict().items())
    clips = MotionClips(data_dir, "train", 64)
    x = src.normalize(torch.from_numpy(np.load(data_dir / "norm_joint_vecs" / f"{clips.ids[0]}.npy")[None, :64]))
    with torch.no_grad():
        assert torch.equal(src.encode(x)[1], ft.encode(x)[1])
        assert not torch.allclose(src.decode(*src.encode(x)[:1], torch.zeros(1, 10)),
                                  ft.decode(*ft.encode(x)[:1], torch.zeros(1, 10)))
    # another network, a missing source, or freezing without a source are refused by name
    with pytest.raises(ShapeMoveError, match="another network.*width"):
        train_vae(data_dir, tmp_path / "w", SAVAEConfig(width=24, depth=1, shape_hidden=16, train=TrainSettings(
            steps=1, batch_size=4, init_from=str(tmp_path / "src" / "savae.pt"))), body=body, device="cpu", verbose=False)
    with pytest.raises(ShapeMoveError, match="not found"):
        train_vae(data_dir, tmp_path / "m", tiny_config(init_from=str(tmp_path / "nope.pt")), body=body, device="cpu", verbose=False)
    with pytest.raises(ShapeMoveError, match="freeze needs train.init_from"):
        tiny_config(freeze=("encoder",)).validate()
    with pytest.raises(ShapeMoveError, match="unknown part.*'encodr'"):
        tiny_config(init_from="x.pt", freeze=("encodr",)).validate()


def test_wider_decoder_refit_on_frozen_codes(data_dir, body, tmp_path):
    """A base decoder of another width (``decoder_width``) trained anew on a codec's frozen codes:
    every token and the shape embedding come from the source, the decoder has the new width and
    decodes; widening a frozen decoder is refused by name."""
    train_vae(data_dir, tmp_path / "src", tiny_config(), body=body, device="cpu", verbose=False)
    src_path = str(tmp_path / "src" / "savae.pt")
    src = load_savae(src_path)
    cfg = tiny_config(steps=2, init_from=src_path, freeze=("encoder", "quantizer", "shape_embedding"))
    cfg.decoder_width = 24
    train_vae(data_dir, tmp_path / "wide", cfg, body=body, device="cpu", verbose=False)
    wide = load_savae(tmp_path / "wide" / "savae.pt")
    assert wide.cfg.width == 16 and wide.cfg.base_decoder_width == 24 and src.cfg.base_decoder_width == 16
    assert wide.decoder.net[0].out_channels == 24 and src.decoder.net[0].out_channels == 16
    for part in ("encoder", "shape_embedding"):
        for name, v in getattr(src, part).state_dict().items():
            assert torch.equal(v, getattr(wide, part).state_dict()[name]), (part, name)
    clips = MotionClips(data_dir, "train", 64)
    x = src.normalize(torch.from_numpy(np.load(data_dir / "norm_joint_vecs" / f"{clips.ids[0]}.npy")[None, :64]))
    with torch.no_grad():
        codes, idx = wide.encode(x)
        assert torch.equal(idx, src.encode(x)[1])
        assert wide.decode(codes, torch.zeros(1, 10)).shape == (1, 64, 263)
    frozen = tiny_config(steps=1, init_from=src_path, freeze=("encoder", "quantizer", "decoder"))
    frozen.decoder_width = 24
    with pytest.raises(ShapeMoveError, match="another network.*decoder_width"):
        train_vae(data_dir, tmp_path / "frozen", frozen, body=body, device="cpu", verbose=False)
    widened = tiny_config(steps=1, init_from=src_path, freeze=("encoder", "quantizer"))
    widened.decoder_width, widened.residual_levels = 24, (8, 5, 5, 5)   # a residual branch copies the old decoder
    with pytest.raises(ShapeMoveError, match="another network.*decoder_width"):
        train_vae(data_dir, tmp_path / "both", widened, body=body, device="cpu", verbose=False)
    with pytest.raises(ShapeMoveError, match="decoder_width must be >= 0"):
        SAVAEConfig(decoder_width=-1).validate()


def test_cli_train_vae(data_dir, tmp_path):
    from shapemove.cli import main

    cfg_path = tmp_path / "cfg.json"
    cfg_path.write_text(json.dumps({"base": "small", "width": 16, "depth": 1, "shape_hidden": 16,
                                    "train": {"batch_size": 2, "warmup_steps": 1, "log_every": 1}}))
    assert main(["train", "vae", "--data", str(data_dir), "--config", str(cfg_path), "--out", str(tmp_path / "run"),
                 "--steps", "2", "--device", "cpu", "--quiet"]) == 0
    assert load_savae(tmp_path / "run" / "savae.pt").cfg.width == 16
    assert main(["train", "vae", "--data", str(tmp_path / "nowhere"), "--out", str(tmp_path / "x"), "--quiet"]) == 2


@pytest.mark.slow  # ~16 s on 2 shared cores: two fresh Python processes importing torch
def test_torchrun_two_processes(data_dir, tmp_path):
    torchrun = Path(sys.executable).with_name("torchrun")
    if not torchrun.exists():
        pytest.skip("torchrun not installed next to the Python interpreter")
    cfg_path = tmp_path / "cfg.json"
    cfg_path.write_text(json.dumps({"width": 16, "depth": 1, "shape_hidden": 16,
                                    "train": {"batch_size": 4, "warmup_steps": 1, "log_every": 1, "val_every": 3,
                                              "val_batches": 1, "ckpt_every": 2}}))
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    t0 = time.time()
    proc = subprocess.run([str(torchrun), "--standalone", "--nproc_per_node", "2", "-m", "shapemove", "train", "vae",
                           "--data", str(data_dir), "--config", str(cfg_path), "--out", str(tmp_path / "ddp"),
                           "--steps", "3", "--device", "cpu", "--quiet"],
                          env=env, capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    ckpt = load_checkpoint(tmp_path / "ddp" / "last.pt")
    assert ckpt["step"] == 3 and ckpt["metadata"]["body"]
    assert all(torch.isfinite(v).all() for v in ckpt["model"].values() if v.is_floating_point())
    log = [json.loads(line) for line in (tmp_path / "ddp" / "log.jsonl").read_text().splitlines()]
    assert [r["step"] for r in log] == [1, 2, 3]                        # rank 0 alone writes the log
    print(f"torchrun 2 processes, 3 steps: {time.time() - t0:.1f} s")


def test_a_run_fitted_to_minutes_resumes_to_the_same_count(data_dir, body, tmp_path, monkeypatch):
    """--minutes fits the step count once (after the first timed steps: here fitted to 30 whatever
    this machine's speed); a resumed run with --minutes ends at that count, not at the config's
    ceiling (its learning-rate schedule does not jump)."""
    import shapemove.core.train.train_vae as tv

    monkeypatch.setattr(tv, "fitted_steps", lambda step, *a: 30)
    cfg = tiny_config(steps=5000, warmup_steps=40, log_every=1000, val_every=100000, ckpt_every=100000)
    calls = []

    def cancel_after_25():
        calls.append(1)
        return len(calls) > 25

    run = tmp_path / "fitted"
    train_vae(data_dir, run, cfg, body=body, device="cpu", verbose=False, minutes=1.0, cancel=cancel_after_25)
    ckpt = load_checkpoint(run / "last.pt")
    assert ckpt["step"] == 25 and ckpt["total_steps"] == 30
    done = train_vae(data_dir, run, cfg, body=body, device="cpu", verbose=False, resume=True, minutes=1.0)
    assert done["step"] == 30 and load_checkpoint(run / "last.pt")["step"] == 30
    # an explicit --steps still extends it
    assert train_vae(data_dir, run, cfg, body=body, device="cpu", verbose=False, resume=True, steps=32)["step"] == 32


@pytest.mark.slow  # ~15 s: a fresh Python process importing torch
def test_kill_stops_training_at_the_end_of_a_step_with_last_pt(data_dir, tmp_path):
    """SIGTERM (and Ctrl-C) stop `train vae` after the step in hand with last.pt written, long
    before its next checkpoint; --resume continues from there."""
    import signal
    import subprocess
    import time

    cfg_path = tmp_path / "cfg.json"
    cfg_path.write_text(json.dumps({"base": "small", "width": 16, "depth": 1, "shape_hidden": 16,
                                    "train": {"steps": 100000, "batch_size": 2, "warmup_steps": 1, "log_every": 1,
                                              "ckpt_every": 100000, "val_every": 100000}}))
    run = tmp_path / "run"
    cmd = [sys.executable, "-m", "shapemove", "train", "vae", "--data", str(data_dir), "--config", str(cfg_path),
           "--out", str(run), "--device", "cpu", "--quiet"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    log = run / "log.jsonl"
    deadline = time.time() + 120
    while time.time() < deadline and not (log.is_file() and len(log.read_text().splitlines()) >= 3):
        time.sleep(0.2)
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert "stopping after this step" in err and "--resume continues it" in out
    step = load_checkpoint(run / "last.pt")["step"]
    assert 3 <= step < 100000 and not (run / "savae.pt").exists()
    again = subprocess.run(cmd + ["--resume", "--steps", str(step + 2)], capture_output=True, text=True, timeout=180)
    assert again.returncode == 0, again.stderr
    assert load_checkpoint(run / "last.pt")["step"] == step + 2 and (run / "savae.pt").exists()
