"""tools/gpu_codec.py: the pack keeps the takes to under a millimetre, the features rebuilt from it
are the builder's own, and the three steps (pack, train, unpack) give a codec that loads."""
from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

TOOL = Path(__file__).resolve().parents[1] / "tools" / "gpu_codec.py"


def _tool():
    spec = importlib.util.spec_from_file_location("gpu_codec", TOOL)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["gpu_codec"] = mod       # the rebuild's worker processes pickle its functions by module name
    spec.loader.exec_module(mod)
    return mod


def test_squeeze_keeps_every_clip_within_half_a_step():
    tool = _tool()
    rng = np.random.default_rng(0)
    lengths = np.array([5, 1, 7, 30])
    a = np.cumsum(rng.normal(0, 0.05, (43, 22, 3)), axis=0) + 3.0      # clips that do not start at zero
    b = tool.squeeze(a, 1e-3, lengths)
    assert b.dtype == np.uint8
    back = tool.unsqueeze(b, 1e-3, lengths, (22, 3))
    assert back.shape == a.shape and np.abs(back - a).max() <= 0.5e-3 + 1e-6
    with pytest.raises(ValueError):
        tool.squeeze(np.array([[0.0], [40.0]]), 1e-3, np.array([2]))   # a jump int16 cannot hold


@pytest.mark.slow
def test_pack_rebuild_train_unpack(tiny_dataset, tmp_path):
    tool = _tool()
    pack = tmp_path / "pack"
    tool.main(["pack", "--data", str(tiny_dataset), "--out", str(pack), "--limit", "3"])
    clips = json.loads((pack / "clips.json").read_text())
    assert len(clips) == 3 and all(c["split"] in ("train", "val") for c in clips)
    built = tool.rebuild(pack, tmp_path / "built", bodies=1, workers=1)
    folder = tmp_path / "built"
    for c in clips:
        cid = c["id"]
        # the take on its own body: the builder's features again (rotations rounded to 1e-3 rad)
        mine = np.load(folder / "new_joint_vecs" / f"{cid}.npy")
        theirs = np.load(tiny_dataset / "new_joint_vecs" / f"{cid}.npy")
        assert mine.shape == theirs.shape
        ric = slice(4, 67)
        assert np.abs(mine[:, ric] - theirs[:, ric]).max() < 0.01                     # joints within 1 cm
        norm = np.load(folder / "norm_joint_vecs" / f"{cid}.npy")
        assert np.abs(norm[:, ric] - np.load(tiny_dataset / "norm_joint_vecs" / f"{cid}.npy")[:, ric]).max() < 0.01
    train = [c["id"] for c in clips if c["split"] == "train"]
    ids = (folder / "train.txt").read_text().split()
    assert len(ids) == 4 * len(train)          # own body and one sampled body, each also mirrored
    assert built["takes_used"] == 3
    config = tmp_path / "tiny.json"
    config.write_text(json.dumps({"base": "tiny", "train": {"steps": 3, "window": 32, "action_balance": 0.5,
                                                              "active_windows": 0.5}}))
    out = tmp_path / "out"
    tool.main(["train", "--pack", str(pack), "--config", str(config), "--minutes", "5", "--bodies", "0",
               "--workers", "1", "--work", str(tmp_path / "work" / "built"), "--out", str(out)])
    assert json.loads((out / "summary.json").read_text())["metrics"]["step"] == 3
    tool.main(["unpack", "--state", str(out), "--out", str(tmp_path / "codec")])
    from shapemove.core.models.savae import load_savae

    vae = load_savae(tmp_path / "codec" / "savae.pt")
    assert vae.metadata["step"] == 3 and vae.cfg.train.resident
