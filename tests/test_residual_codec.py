"""The SA-VAE's residual code: tokens that pack it, a codec widened from one without it (the same
base tokens and, untrained, the same decode), training it with the base frozen, and every place
the T5 reads tokens taking the base codes alone."""
import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.models.motion_codes import base_of, pack, unpack
from shapemove.core.models.savae import PARTS, SAVAE, SAVAEConfig, TrainSettings, add_residual, load_savae

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
        assert torch.equal(wide.decode(codes, betas), base.decode(codes, betas))   # decoded by the same decoder
        res, ridx = wide.encode_residual(x)
        assert res.shape == (2, 8, 4) and int(ridx.max()) < 1000
        # the residual branch starts as a copy of the base one, but reads the residual too
        assert not torch.allclose(wide.decode(codes, betas, res), base.decode(codes, betas), atol=1e-4)
        tokens = wide.encode_tokens(x)
        assert torch.equal(base_of(tokens, 1000), idx) and bool((tokens >= 1000).all())
        # packed tokens decode through the residual branch; base tokens, or any step without a
        # residual, through the base decoder
        assert torch.allclose(wide.decode_tokens_long(tokens, betas), wide.decode(codes, betas, res), atol=1e-5)
        assert torch.equal(wide.decode_tokens_long(idx, betas), base.decode_tokens_long(idx, betas))
        mixed = tokens.clone()
        mixed[:, 4:] = idx[:, 4:]
        assert torch.equal(wide.decode_tokens_long(mixed, betas), base.decode_tokens_long(idx, betas))
        # a codec without a residual decodes the base of packed tokens
        assert torch.equal(base.decode_tokens_long(tokens, betas), base.decode_tokens_long(idx, betas))
    with pytest.raises(ShapeMoveError, match="no residual code"):
        base.encode_residual(x)
    with pytest.raises(ShapeMoveError, match="no residual code to decode"):
        base.decode(codes, betas, res)
    with pytest.raises(ShapeMoveError, match="needs a codec without"):
        add_residual(base, wide)
    with pytest.raises(ShapeMoveError, match="residual codes must be"):
        wide.decode(codes, betas, res[:, :4])


def test_config_refuses_bad_residual_settings():
    with pytest.raises(ShapeMoveError, match="residual_dropout"):
        SAVAEConfig.from_dict({"base": "tiny", "residual_levels": [8, 5, 5, 5], "residual_dropout": 1.5})
    with pytest.raises(ShapeMoveError, match="may not be larger"):
        SAVAEConfig.from_dict({"base": "tiny", "residual_levels": [8, 8, 8, 8]})
    with pytest.raises(ShapeMoveError, match="residual parts need residual_levels"):
        tiny(init_from="x.pt", freeze=("residual_encoder",)).validate()
    everything = PARTS
    with pytest.raises(ShapeMoveError, match="leaves nothing to train"):
        tiny([8, 5, 5, 5], init_from="x.pt", freeze=everything).validate()
    assert tiny([8, 5, 5, 5], init_from="x.pt", freeze=everything[4:]).trains_base
    assert not tiny([8, 5, 5, 5], init_from="x.pt", freeze=everything[:4]).trains_base
    assert tiny().trains_base
    assert tiny([8, 5, 5, 5]).residual_input_dim == 9


def test_residual_training_keeps_every_base_token(tiny_dataset, tmp_path):
    """A residual branch trained onto a codec, its base parts frozen: every base token and the base
    decoding stay bit for bit (the T5 and what it generates are unchanged), the residual branch
    learns, the checkpoint loads as a residual codec whose full tokens decode otherwise than their
    base codes, and a fine-tune of it starts from it while one of another residual is refused."""
    from shapemove.core.train.motion_dataset import MotionClips
    from shapemove.core.train.train_vae import train_vae

    train_vae(tiny_dataset, tmp_path / "src", tiny(steps=20, lr=3e-3), device="cpu", verbose=False)
    src = load_savae(tmp_path / "src" / "savae.pt")
    frozen = ("encoder", "quantizer", "decoder", "shape_embedding")
    cfg = tiny([8, 5, 5, 5], steps=10, lr=3e-3, init_from=str(tmp_path / "src" / "savae.pt"), freeze=frozen,
               val_every=1000)
    train_vae(tiny_dataset, tmp_path / "res", cfg, device="cpu", verbose=False)
    res = load_savae(tmp_path / "res" / "savae.pt")
    assert res.has_residual and not src.has_residual and res.cfg.residual_dropout == 0.5
    for name, v in src.state_dict().items():
        assert torch.equal(v, res.state_dict()[name]), name                          # the base codec as it was
    start = SAVAE(cfg)
    add_residual(start, src)
    for part in ("residual_encoder.net.6.weight", "residual_decoder.lift.weight", "residual_shape_embedding.mlp.0.weight"):
        assert not torch.equal(res.state_dict()[part], start.state_dict()[part]), part   # the branch learnt
    item = MotionClips(tiny_dataset, "train", 32)[(0, 0)]
    x, b = item["x"][None], item["betas"][None]
    with torch.no_grad():
        tokens = res.encode_tokens(x)
        assert torch.equal(base_of(tokens, 1000), src.encode(x)[1])
        assert torch.equal(res.decode_tokens_long(base_of(tokens, 1000), b), src.decode(src.encode(x)[0], b))
        assert not torch.allclose(res.decode_tokens_long(tokens, b), res.decode_tokens_long(base_of(tokens, 1000), b),
                                  atol=1e-4)
    again = tiny([8, 5, 5, 5], steps=2, init_from=str(tmp_path / "res" / "savae.pt"), freeze=frozen)
    train_vae(tiny_dataset, tmp_path / "again", again, device="cpu", verbose=False)
    with pytest.raises(ShapeMoveError, match="another network.*residual_levels"):
        train_vae(tiny_dataset, tmp_path / "other", tiny([5, 5, 5], steps=2, init_from=str(tmp_path / "res" / "savae.pt")),
                  device="cpu", verbose=False)


def test_base_decoder_fine_tuned_under_a_residual_branch(tiny_dataset, tmp_path):
    """Every residual part frozen, the encoder and quantizer too: training goes through the base
    path, so the base decoder learns while every token and the residual branch (what captured motion
    decodes through) stay bit for bit."""
    from shapemove.core.train.motion_dataset import MotionClips
    from shapemove.core.train.train_vae import train_vae

    train_vae(tiny_dataset, tmp_path / "src", tiny(steps=20, lr=3e-3), device="cpu", verbose=False)
    res_cfg = tiny([8, 5, 5, 5], steps=10, lr=3e-3, init_from=str(tmp_path / "src" / "savae.pt"),
                   freeze=("encoder", "quantizer", "decoder", "shape_embedding"), val_every=1000)
    train_vae(tiny_dataset, tmp_path / "res", res_cfg, device="cpu", verbose=False)
    frozen = ("encoder", "quantizer", "residual_encoder", "residual_decoder", "residual_shape_embedding")
    cfg = tiny([8, 5, 5, 5], steps=10, lr=3e-3, init_from=str(tmp_path / "res" / "savae.pt"), freeze=frozen,
               val_every=5)
    assert cfg.trains_base
    train_vae(tiny_dataset, tmp_path / "dec", cfg, device="cpu", verbose=False)
    res, dec = load_savae(tmp_path / "res" / "savae.pt"), load_savae(tmp_path / "dec" / "savae.pt")
    before, after = res.state_dict(), dec.state_dict()
    for name, v in before.items():
        if name.startswith(("decoder.", "shape_embedding.")):
            continue
        assert torch.equal(v, after[name]), name                  # encoders and residual branch as they were
    assert not torch.equal(before["decoder.lift.weight"], after["decoder.lift.weight"])   # the base decoder learnt
    item = MotionClips(tiny_dataset, "train", 32)[(0, 0)]
    x, b = item["x"][None], item["betas"][None]
    with torch.no_grad():
        tokens = dec.encode_tokens(x)
        assert torch.equal(tokens, res.encode_tokens(x))
        assert torch.equal(dec.decode_tokens_long(tokens, b), res.decode_tokens_long(tokens, b))
        base = base_of(tokens, 1000)
        assert not torch.allclose(dec.decode_tokens_long(base, b), res.decode_tokens_long(base, b), atol=1e-4)


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
