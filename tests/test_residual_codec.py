"""The SA-VAE's residual code: tokens that pack it, a codec widened from one without it (the same
base tokens and, untrained, the same decode), training it with the base frozen, and every place
the T5 reads tokens taking the base codes alone."""
import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.models.motion_codes import base_of, pack, unpack
from shapemove.core.models.savae import SAVAE, SAVAEConfig, TrainSettings, add_residual, load_savae

pytestmark = pytest.mark.usefixtures("one_thread")


def tiny(residual=(), **train) -> SAVAEConfig:
    settings = dict(steps=6, batch_size=4, warmup_steps=2, log_every=1, val_every=3, val_batches=1, ckpt_every=2)
    return SAVAEConfig(width=16, depth=1, shape_hidden=16, residual_levels=tuple(residual),
                       train=TrainSettings(**{**settings, **train}))


def test_pack_round_trip():
    base = np.array([0, 999, 17, 500])
    res = np.array([-1, 0, 999, 3])
    tok = pack(base, res, 1000)
    assert tok.tolist() == [0, 1999, 1000017, 4500]           # a step without a residual is its base index
    b, r = unpack(tok, 1000)
    assert b.tolist() == base.tolist() and r.tolist() == res.tolist()
    assert base_of([1999, 5, 1000017], 1000) == [999, 5, 17]
    assert base_of(torch.tensor([4500]), 1000).tolist() == [500]
    with pytest.raises(ShapeMoveError, match=">= 0"):
        unpack(np.array([-3]), 1000)


def test_widened_codec_keeps_the_base():
    torch.manual_seed(0)
    base = SAVAE(tiny()).eval()
    wide = SAVAE(tiny([8, 5, 5, 5])).eval()
    add_residual(wide, base)
    x, betas = torch.randn(2, 32, 263), torch.randn(2, 10)
    with torch.no_grad():
        codes, idx = base.encode(x)
        assert torch.equal(wide.encode(x)[1], idx)                       # the same base tokens
        res, ridx = wide.encode_residual(x)
        assert res.shape == (2, 8, 4) and int(ridx.max()) < 1000
        # untrained, the base codes alone decode exactly as the base codec's; the residual changes it
        assert torch.allclose(wide.decode(codes, betas), base.decode(codes, betas), atol=1e-6)
        assert not torch.allclose(wide.decode(codes, betas, res), base.decode(codes, betas), atol=1e-4)
        tokens = wide.encode_tokens(x)
        assert torch.equal(base_of(tokens, 1000), idx) and bool((tokens >= 1000).all())
        # the packed tokens decode as the codes do (per step: a step without a residual reads base alone)
        full = wide.decode_tokens_long(tokens, betas)
        assert torch.allclose(full, wide.decode(codes, betas, res), atol=1e-5)
        assert not torch.allclose(full, wide.decode(codes, betas), atol=1e-3)
        assert torch.allclose(wide.decode_tokens_long(idx, betas), wide.decode(codes, betas), atol=1e-5)
        mixed = tokens.clone()
        mixed[:, 4:] = idx[:, 4:]
        present = torch.zeros(2, 8)
        present[:, :4] = 1
        assert torch.allclose(wide.decode_tokens_long(mixed, betas), wide.decode(codes, betas, res, present), atol=1e-5)
        # a codec without a residual decodes the base of packed tokens
        assert torch.allclose(base.decode_tokens_long(tokens, betas), base.decode(codes, betas), atol=1e-6)
    with pytest.raises(ShapeMoveError, match="no residual code"):
        base.encode_residual(x)
    with pytest.raises(ShapeMoveError, match="needs a codec without"):
        add_residual(base, wide)
    with pytest.raises(ShapeMoveError, match="residual codes must be"):
        wide.decode(codes, betas, res[:, :4])


def test_config_refuses_bad_residual_settings():
    with pytest.raises(ShapeMoveError, match="residual_dropout"):
        SAVAEConfig.from_dict({"base": "tiny", "residual_levels": [8, 5, 5, 5], "residual_dropout": 1.5})
    with pytest.raises(ShapeMoveError, match="may not be larger"):
        SAVAEConfig.from_dict({"base": "tiny", "residual_levels": [8, 8, 8, 8]})
    with pytest.raises(ShapeMoveError, match="residual_encoder needs residual_levels"):
        tiny(init_from="x.pt", freeze=("residual_encoder",)).validate()
    assert tiny([8, 5, 5, 5]).decoder_input_dim == 9 and tiny().decoder_input_dim == 4


def test_residual_training_keeps_every_base_token(tiny_dataset, tmp_path):
    """A residual code trained onto a codec with its encoder and quantizer frozen: every base token
    stays (the T5 needs no retraining), the residual encoder and the decoder learn, the checkpoint
    loads as a residual codec whose full tokens decode otherwise than their base codes alone, and a
    fine-tune of it starts from it (same network) while one of another residual is refused."""
    from shapemove.core.train.motion_dataset import MotionClips
    from shapemove.core.train.train_vae import train_vae

    train_vae(tiny_dataset, tmp_path / "src", tiny(steps=20, lr=3e-3), device="cpu", verbose=False)
    src = load_savae(tmp_path / "src" / "savae.pt")
    cfg = tiny([8, 5, 5, 5], steps=10, lr=3e-3, init_from=str(tmp_path / "src" / "savae.pt"),
               freeze=("encoder", "quantizer"), val_every=1000)
    train_vae(tiny_dataset, tmp_path / "res", cfg, device="cpu", verbose=False)
    res = load_savae(tmp_path / "res" / "savae.pt")
    assert res.has_residual and not src.has_residual and res.cfg.residual_dropout == 0.5
    start = SAVAE(cfg)
    add_residual(start, src)
    last = f"residual_encoder.net.{len(res.encoder.net) - 1}.weight"
    assert not torch.equal(res.state_dict()[last], start.state_dict()[last])           # the residual learnt
    assert not torch.equal(res.decoder.lift.weight, start.decoder.lift.weight)
    item = MotionClips(tiny_dataset, "train", 32)[(0, 0)]
    x, b = item["x"][None], item["betas"][None]
    with torch.no_grad():
        assert torch.equal(src.encode(x)[1], res.encode(x)[1])
        tokens = res.encode_tokens(x)
        assert not torch.allclose(res.decode_tokens_long(tokens, b), res.decode_tokens_long(base_of(tokens, 1000), b),
                                  atol=1e-4)
    again = tiny([8, 5, 5, 5], steps=2, init_from=str(tmp_path / "res" / "savae.pt"), freeze=("encoder", "quantizer"))
    train_vae(tiny_dataset, tmp_path / "again", again, device="cpu", verbose=False)
    with pytest.raises(ShapeMoveError, match="another network.*residual_levels"):
        train_vae(tiny_dataset, tmp_path / "other", tiny([5, 5, 5], steps=2, init_from=str(tmp_path / "res" / "savae.pt")),
                  device="cpu", verbose=False)


def test_the_t5_reads_base_codes_only():
    """Prefixes given to the T5 and the retrieved clips it reads drop a packed residual."""
    from shapemove.core.models.constrained_decoding import _prefix_rows
    from shapemove.core.models.motion_memory import MotionMemory

    assert _prefix_rows([1999, 5], 2, 1000) == [[999, 5], [999, 5]]
    with pytest.raises(ValueError, match="motion tokens"):
        _prefix_rows([1000 * 1001], 1, 1000)
    assert _prefix_rows([[1000017], [3]], 2, 1000) == [[17], [3]]
    mem = MotionMemory.empty()

    class Reader:  # unit sentence vectors for two texts, as MiniLM would give them
        def states(self, texts):
            x = torch.zeros(len(texts), 1, 384)
            for i, t in enumerate(texts):
                x[i, 0, 0 if "walk" in t else 1] = 1.0
            return x, torch.ones(len(texts), 1, dtype=torch.bool)

    mem.add_clips(["a", "b"], [["a person walks"], ["a person waves"]],
                  [np.array([1999, 1000017, 4]), np.array([7, 8])], Reader())
    ids, sims = mem.lookup(Reader(), ["someone walks"], k=1, max_codes=4)
    assert ids[0, 0].tolist() == [999, 17, 4, -1] and float(sims[0, 0]) > 0.99
    assert mem.clip_tokens[0].tolist() == [1999, 1000017, 4]      # decoding gets the full tokens


def test_memory_keeps_packed_tokens(tmp_path):
    from shapemove.core.models.motion_memory import MotionMemory

    mem = MotionMemory(["t"], torch.nn.functional.normalize(torch.ones(1, 384), dim=-1), [[0]], ["c"],
                       [np.array([1000999, 5, 2000000])])
    mem.save(tmp_path)
    back = MotionMemory.load(tmp_path)
    assert back.clip_tokens[0].tolist() == [1000999, 5, 2000000]
