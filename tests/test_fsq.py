"""FSQ: index <-> code bijection, bounding/rounding, straight-through gradient, usage stats."""
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.models.fsq import FSQ, codebook_usage


def inverse_bound(fsq: FSQ, codes: torch.Tensor) -> torch.Tensor:
    """z with bound(z) == codes * half_width exactly (hand-inverted tanh bound)."""
    return torch.atanh((codes * fsq.half_width + fsq.offset) / fsq.half_l) - fsq.shift


def test_indices_codes_round_trip_over_the_whole_codebook():
    fsq = FSQ((8, 5, 5, 5))
    assert fsq.codebook_size == 1000 and fsq.dim == 4
    idx = torch.arange(1000)
    codes = fsq.indices_to_codes(idx)
    assert codes.shape == (1000, 4)
    assert torch.equal(fsq.codes_to_indices(codes), idx)
    assert len({tuple(c) for c in codes.tolist()}) == 1000          # all codes distinct
    # per-channel grids: 8 levels -> k/4 for k in -4..3; 5 levels -> k/2 for k in -2..2
    assert sorted(set(codes[:, 0].tolist())) == [k / 4 for k in range(-4, 4)]
    for c in (1, 2, 3):
        assert sorted(set(codes[:, c].tolist())) == [k / 2 for k in range(-2, 3)]
    # mixed radix: index 1 moves channel 0 by one step, index 8 channel 1, 40 channel 2, 200 channel 3
    for i, ch in ((1, 0), (8, 1), (40, 2), (200, 3)):
        d = fsq.indices_to_codes(torch.tensor(i)) - fsq.indices_to_codes(torch.tensor(0))
        assert torch.count_nonzero(d) == 1 and d[ch] > 0


def test_quantize_of_code_values_is_identity():
    fsq = FSQ((8, 5, 5, 5))
    codes = fsq.indices_to_codes(torch.arange(1000))
    assert torch.allclose(fsq.quantize(inverse_bound(fsq, codes)), codes, atol=0)
    z = torch.randn(64, 4) * 3
    q = fsq.quantize(z)
    assert torch.equal(fsq.indices_to_codes(fsq.codes_to_indices(q)), q)     # every output is a code
    assert q.min() >= -1 and q.max() <= 1
    # huge inputs saturate at the extreme codes, even level: -4/4 .. 3/4
    sat = fsq.quantize(torch.tensor([[50.0, 50, 50, 50], [-50, -50, -50, -50]]))
    assert sat.tolist() == [[0.75, 1, 1, 1], [-1, -1, -1, -1]]


def test_straight_through_gradient():
    fsq = FSQ((8, 5, 5, 5))
    z = (torch.randn(10, 4) * 0.7).requires_grad_()
    w = torch.randn(10, 4)
    (fsq.quantize(z) * w).sum().backward()
    # rounding passes gradients unchanged: d/dz [tanh(z + shift) * half_l / half_width]
    expected = w * (1 - torch.tanh(z.detach() + fsq.shift) ** 2) * fsq.half_l / fsq.half_width
    assert torch.allclose(z.grad, expected, atol=1e-6)
    codes, indices = fsq(z)
    assert indices.dtype == torch.int64 and torch.equal(fsq.indices_to_codes(indices), codes.detach())


def test_codebook_usage():
    u = codebook_usage(torch.arange(1000).repeat(3), 1000)
    assert u["used_fraction"] == 1.0 and u["perplexity"] == pytest.approx(1000, rel=1e-9)
    u = codebook_usage(torch.full((50,), 7), 1000)
    assert u["used_fraction"] == 0.001 and u["perplexity"] == pytest.approx(1.0)
    u = codebook_usage(torch.tensor([0, 0, 1, 1]), 1000)        # two equally used codes
    assert u["perplexity"] == pytest.approx(2.0)


def test_bad_input():
    with pytest.raises(ShapeMoveError):
        FSQ((8, 1))
    fsq = FSQ((8, 5, 5, 5))
    with pytest.raises(ShapeMoveError, match="out of range"):
        fsq.indices_to_codes(torch.tensor([1000]))
    with pytest.raises(ShapeMoveError, match="channels"):
        fsq.codes_to_indices(torch.zeros(3, 5))


def test_default_codebook_is_the_motion_vocabulary():
    from shapemove.core.constants import FSQ_LEVELS, NUM_CODES
    from shapemove.core.models.savae import SAVAEConfig
    from shapemove.core.models.tokenizer import motion_tokens

    assert FSQ(SAVAEConfig().levels).codebook_size == NUM_CODES == 8 * 5 * 5 * 5 == len(motion_tokens())
    assert FSQ().levels_list == list(FSQ_LEVELS)
