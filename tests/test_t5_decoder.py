"""The plain-torch T5 decoder equals transformers' T5Stack (decoder) on the same weights: outputs
with padded encoder states, the key/value cache, gradients; and it loads a T5Stack's state dict."""
import pytest
import torch

from shapemove.core.models.t5_decoder import T5Decoder, T5DecoderConfig


@pytest.fixture(scope="module")
def pair():
    from transformers import T5Config
    from transformers.models.t5.modeling_t5 import T5Stack

    c = T5DecoderConfig(vocab_size=57, d_model=32, d_ff=48, d_kv=8, num_heads=4, num_layers=3, dropout_rate=0.0,
                        relative_attention_num_buckets=8, relative_attention_max_distance=20)
    torch.manual_seed(0)
    mine = T5Decoder(c).eval()
    ref_cfg = T5Config(vocab_size=c.vocab_size, d_model=c.d_model, d_ff=c.d_ff, d_kv=c.d_kv, num_heads=c.num_heads,
                       num_layers=c.num_layers, dropout_rate=0.0, relative_attention_num_buckets=8,
                       relative_attention_max_distance=20, is_decoder=True, is_encoder_decoder=False, use_cache=True)
    ref = T5Stack(ref_cfg).eval()
    ref.load_state_dict(mine.state_dict(), strict=True)  # the same parameter names and shapes
    return mine, ref


def _inputs(T=30):
    g = torch.Generator().manual_seed(1)
    ids = torch.randint(0, 57, (2, T), generator=g)
    enc = torch.randn(2, 7, 32, generator=g)
    mask = torch.ones(2, 7, dtype=torch.bool)
    mask[1, 4:] = False
    return ids, enc, mask


def test_same_outputs_as_t5stack(pair):
    mine, ref = pair
    ids, enc, mask = _inputs(30)  # beyond the exact buckets: the log buckets are used too
    a, _ = mine(ids, enc, mask)
    b = ref(input_ids=ids, encoder_hidden_states=enc, encoder_attention_mask=mask.long(), use_cache=False).last_hidden_state
    torch.testing.assert_close(a, b, atol=1e-5, rtol=1e-4)


def test_cache_gives_the_same_states_step_by_step(pair):
    mine, _ = pair
    ids, enc, mask = _inputs(12)
    full, _ = mine(ids, enc, mask)
    out, cache = mine(ids[:, :3], enc, mask, use_cache=True)
    steps = [out]
    for t in range(3, 12):
        out, cache = mine(ids[:, t:t + 1], enc, mask, cache=cache, use_cache=True)
        steps.append(out)
    torch.testing.assert_close(torch.cat(steps, 1), full, atol=1e-5, rtol=1e-4)


def test_same_gradients_as_t5stack(pair):
    mine, ref = pair
    ids, enc, mask = _inputs(10)
    mine.zero_grad()
    ref.zero_grad()
    mine(ids, enc, mask)[0].square().sum().backward()
    ref(input_ids=ids, encoder_hidden_states=enc, encoder_attention_mask=mask.long(),
        use_cache=False).last_hidden_state.square().sum().backward()
    grads = dict(ref.named_parameters())
    for name, p in mine.named_parameters():
        torch.testing.assert_close(p.grad, grads[name].grad, atol=1e-4, rtol=1e-3, msg=name)


def test_config_reads_a_t5config_json():
    from transformers import T5Config

    j = T5Config(vocab_size=9, d_model=16, d_ff=32, d_kv=4, num_heads=4, num_decoder_layers=2, num_layers=2).to_dict()
    c = T5DecoderConfig.from_dict(j)
    assert (c.vocab_size, c.d_model, c.d_ff, c.d_kv, c.num_heads, c.num_layers) == (9, 16, 32, 4, 4, 2)
