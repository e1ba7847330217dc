"""Classifier-free guidance in constrained decoding (null_share training, guidance at generation)."""
import pytest
import torch

from tiny_models import tiny_bundle  # noqa: F401  (session fixture)

from shapemove.core.errors import ShapeMoveError
from shapemove.core.generation.sampling_params import check_guidance


@pytest.mark.parametrize("bad", [-0.1, 21, float("nan"), float("inf"), "2", True])
def test_guidance_is_checked(bad):
    with pytest.raises(ShapeMoveError, match="guidance must be"):
        check_guidance(bad)
    assert check_guidance(None) is None and check_guidance(3) == 3.0


def test_guidance_arithmetic(tiny_bundle):  # noqa: F811
    from shapemove.core.generation.generate import Generator
    from shapemove.core.models.constrained_decoding import decode
    from shapemove.core.models.shapemove_t5 import NULL_PROMPT

    gen = Generator(tiny_bundle[0])
    assert gen.default_guidance == 0.0  # the tiny T5 was trained without null prompts
    t5, prompt = gen.t5, ["a person jumps"] * 3
    inputs = t5.inputs_for(gen.tok, prompt, [None] * 3)
    null = t5.inputs_for(gen.tok, [NULL_PROMPT] * 3, [None] * 3)

    def run(**kw):
        return decode(t5, inputs, 4, 8, temperature=1.0, top_k=50, generator=torch.Generator().manual_seed(5), **kw)

    plain = run()
    # guidance against the prompt itself: cond + s (cond - cond) = cond, the same samples
    assert run(guidance=3.0, null_inputs=inputs).codes == plain.codes
    guided = run(guidance=3.0, null_inputs=null)
    assert guided.codes != plain.codes
    assert torch.equal(guided.betas, plain.betas)  # betas from the conditional rows only
    # greedy: the first code is the argmax of the guided logits, computed here by hand
    enc, mask = t5.encode(*inputs)
    enc0, mask0 = t5.encode(*null)
    v = t5.vocab
    seq = torch.tensor([[v.pad_id, v.beta_id, v.som_id]] * 3)
    with torch.no_grad():
        c = t5.step(enc, mask, seq)[0][:, -1]
        u = t5.step(enc0, mask0, seq)[0][:, -1]
    g = c + 2.0 * (c - u)
    codes = slice(v.first_code_id, v.first_code_id + v.num_codes)
    want = (g[:, codes].argmax(-1)).tolist()
    got = decode(t5, inputs, 4, 8, temperature=0, guidance=2.0, null_inputs=null).codes
    assert [x[0] for x in got] == want
