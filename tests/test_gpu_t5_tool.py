"""tools/gpu_t5.py: the pack that travels to a lent GPU (float16 MiniLM with the word pieces the
texts use, the clips' tokens of one named VAE), a run there, and the model folder made from it here."""
import json
from argparse import Namespace
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import torch

from tiny_models import tiny_bundle  # noqa: F401  (session fixture)
from tool_module import load_tool

ROOT = Path(__file__).resolve().parents[1]


def _tool():
    return load_tool("gpu_t5", "gpu_t5_tool")


def test_pack_train_unpack_round_trip(tiny_bundle, tmp_path, monkeypatch):  # noqa: F811
    from shapemove.core.models import text_encoder as te
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5
    from shapemove.core.train.train_t5 import T5TrainConfig

    tool = _tool()
    model_dir, data = tiny_bundle
    runs = model_dir.parent / "runs"
    vae, tokens = runs / "vae" / "savae.pt", runs / "t5" / "tokens.npz"

    other = tmp_path / "other.npz"  # tokens of another codec: refused by name
    np.savez(other, __vae__=np.array("/elsewhere/savae.pt:1"), a=np.zeros(3, np.int16))
    with pytest.raises(SystemExit, match="/elsewhere/savae.pt, not of"):
        tool.pack(Namespace(data=data, vae=vae, tokens=other, out=tmp_path / "refused"))

    pack = tmp_path / "pack"
    tool.pack(Namespace(data=data, vae=vae, tokens=tokens, out=pack))
    assert (pack / "minilm16.safetensors").stat().st_size < 25 << 20  # the 90 MB encoder does not travel

    captions = [ln for f in sorted((data / "texts").glob("*.txt"))[:12] for ln in f.read_text().splitlines() if ln]
    exact_x, exact_m = te.load_text_encoder().states(captions)
    with monkeypatch.context() as m:  # the packed encoder, loaded where the tool puts it, then forgotten
        m.setattr(te, "_verify", te._verify)
        m.setattr(te, "_loaded", {})
        m.setattr(te, "_cache_dir_override", None)
        tool._encoder_from_pack(pack, tmp_path / "encoder")
        x, mask = te.load_text_encoder().states(captions)
    assert torch.equal(mask, exact_m)
    assert float((x - exact_x).norm() / exact_x.norm()) < 3e-3  # float16 weights: rounding, not another model
    assert te.load_text_encoder().folder != tmp_path / "encoder"

    c = T5TrainConfig.tiny()
    c.steps, c.warmup_steps, c.ckpt_every = 12, 2, 6
    cfg = tmp_path / "tiny_cfg.json"
    cfg.write_text(json.dumps(asdict(c)))
    out = tmp_path / "back"
    out.mkdir()
    tool.train(Namespace(pack=pack, configs=[cfg], minutes=3.0, work=str(tmp_path / "work"), out=out, device="cpu",
                         probe=3, resume=False))
    parts = sorted(out.glob("tiny_cfg.*.safetensors"))
    assert parts

    tool.unpack(Namespace(state=out / "tiny_cfg", data=data, vae=vae, tokens=tokens, out=tmp_path / "model"))
    got, _ = ShapeMoveT5.load(tmp_path / "model" / "t5")
    ck = torch.load(tmp_path / "work" / "tiny_cfg" / "last.pt", map_location="cpu", weights_only=True)
    assert got.info["step"] == ck["step"] == 12
    for k, v in got.lm.state_dict().items():  # the weights trained there, float16-rounded on the way
        assert torch.allclose(v, ck["model"]["lm." + k].float(), atol=2e-3, rtol=1e-3), k


def test_steps_shortened_while_training_end_cleanly(tiny_bundle, tmp_path):  # noqa: F811
    """The tool fits a run's step count to the time left while it trains: the loop and the (empty)
    head phase follow the new count."""
    from shapemove.core.train.train_t5 import T5TrainConfig, train_t5

    model_dir, data = tiny_bundle
    vae = model_dir.parent / "runs" / "vae" / "savae.pt"
    c = T5TrainConfig.tiny()
    c.steps, c.warmup_steps, c.ckpt_every, c.head_steps = 40, 2, 100, 0
    calls = iter(range(1000))

    def shorten():
        if next(calls) == 3:
            c.steps = 9
        return False

    res = train_t5(data, vae, tmp_path / "run", c, device="cpu", verbose=False, cancel=shorten)
    assert res["step"] == 9
    ck = torch.load(tmp_path / "run" / "last.pt", map_location="cpu", weights_only=True)
    assert ck["step"] == 9 and ck["config"]["steps"] == 9


def test_pack_names_a_vae_of_the_repository_and_copies_any_other(tmp_path):
    """The repository travels to the GPU machine anyway: its own VAE file is named, not copied
    (5.5 MB of the 64 MiB that travel); a VAE from elsewhere is copied."""
    tool = _tool()
    shipped = ROOT / "weights" / "default" / "savae.pt"
    inside = tmp_path / "inside"
    inside.mkdir()
    tool._pack_vae(shipped, inside)
    assert (inside / "vae.txt").read_text() == "weights/default/savae.pt"
    assert not (inside / "savae.pt").exists()
    assert tool._vae_of(inside) == shipped

    other = tmp_path / "elsewhere.pt"
    other.write_bytes(b"0123456789")
    (inside / "savae.pt").write_bytes(b"stale")
    tool._pack_vae(other, inside)  # packing again into the same folder: no stale name is left behind
    assert not (inside / "vae.txt").exists()
    assert (inside / "savae.pt").read_bytes() == b"0123456789"
    assert tool._vae_of(inside) == inside / "savae.pt"
