"""One config loader (core/config_presets.py): every trainer takes the same preset names (the
ones `train KIND --config` advertises), rejects others with one sentence, and reads JSON files."""
from __future__ import annotations

import json

import pytest

from shapemove.core.config_presets import PRESETS, load_config
from shapemove.core.errors import ShapeMoveError
from shapemove.core.models.savae import SAVAEConfig
from shapemove.core.train.train_t5 import T5TrainConfig
from shapemove.core.train.train_tma import TMATrainConfig

LOADERS = {"SA-VAE": SAVAEConfig.load, "T5": T5TrainConfig.load, "TMA": TMATrainConfig.load}


@pytest.mark.parametrize("what", LOADERS)
def test_every_trainer_takes_every_preset_and_they_grow(what):
    load = LOADERS[what]
    cfgs = {name: load(name) for name in PRESETS}
    assert load(None) == cfgs["small"]
    if what == "SA-VAE":
        widths = [cfgs[n].width for n in PRESETS]
    elif what == "T5":
        widths = [cfgs[n].size["d_model"] for n in PRESETS]
    else:
        widths = [cfgs[n].model["layers"] * cfgs[n].model["dim"] for n in PRESETS]
    assert widths[0] < widths[1] < widths[2], (what, widths)  # tiny < small < paper
    with pytest.raises(ShapeMoveError, match=f"{what} config 'huge': use tiny, small, paper or a JSON file"):
        load("huge")


def test_the_cli_advertises_the_presets():
    import argparse

    from shapemove.cli import train

    p = argparse.ArgumentParser()
    train.add_arguments(p)
    args = p.parse_args(["t5", "--data", "d", "--out", "o", "--vae", "v.pt", "--config", "paper"])
    assert T5TrainConfig.load(args.config).encoder == "t5"
    assert "tiny | small | paper" in p._subparsers._group_actions[0].choices["vae"].format_help()


def test_json_files_and_their_errors(tmp_path):
    p = tmp_path / "t5.json"
    p.write_text(json.dumps({"steps": 7, "lr": 1e-3}))
    c = T5TrainConfig.load(str(p))
    assert (c.steps, c.lr, c.batch_size) == (7, 1e-3, T5TrainConfig().batch_size)
    p.write_text(json.dumps({"stpes": 7}))
    with pytest.raises(ShapeMoveError, match="unknown T5 config keys"):
        T5TrainConfig.load(str(p))
    p.write_text("[1, 2]")
    with pytest.raises(ShapeMoveError, match="JSON object"):
        TMATrainConfig.load(str(p))
    p.write_text("{not json")
    with pytest.raises(ShapeMoveError, match="not valid JSON"):
        SAVAEConfig.load(str(p))
    p.write_text(json.dumps({"base": "tiny", "width": 24}))
    c = SAVAEConfig.load(str(p))
    assert (c.width, c.depth) == (24, SAVAEConfig.tiny().depth)
    with pytest.raises(ValueError, match="presets"):  # a trainer without all three presets is a bug
        load_config("X", "small", {"small": dict}, lambda d, p: d)
