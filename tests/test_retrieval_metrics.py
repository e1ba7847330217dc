"""R-precision, matching score and FID on constructed embeddings with known answers."""
import numpy as np
import pytest

from shapemove.core.eval.retrieval import fid, matching_score, r_precision


def test_perfect_alignment_gives_full_r_precision():
    rng = np.random.default_rng(0)
    m = rng.standard_normal((64, 8))
    r = r_precision(m.copy(), m, group=32)
    assert r["top1"] == 1.0 and r["top3"] == 1.0


def test_shuffled_pairs_are_near_chance():
    rng = np.random.default_rng(1)
    t = rng.standard_normal((3200, 8))
    m = rng.standard_normal((3200, 8))
    r = r_precision(t, m, group=32)
    assert r["top1"] == pytest.approx(1 / 32, abs=0.01)
    assert r["top3"] == pytest.approx(3 / 32, abs=0.015)


def test_known_rank():
    # text i is closest to motion (i+1) % 4, its own motion is second closest -> top1 0, top2 1
    m = np.array([[0.0], [10.0], [20.0], [30.0]])
    t = m + 6.0  # 6 from its own motion, 4 from the next one
    t[3] = 30 - 6.0  # the last text is 6 from its own motion and 4 from motion 2
    r = r_precision(t, m, top_k=(1, 2), group=4)
    assert r["top1"] == 0.0 and r["top2"] == 1.0


def test_matching_score_and_fid():
    a = np.zeros((5, 3))
    b = np.full((5, 3), [3.0, 4.0, 0.0])
    assert matching_score(a, b) == pytest.approx(5.0)
    rng = np.random.default_rng(2)
    x = rng.standard_normal((4000, 4))
    assert fid(x, x) == pytest.approx(0.0, abs=1e-6)
    # shifting the mean by (2,0,0,0) adds 4 to the FID
    assert fid(x, x + np.array([2.0, 0, 0, 0])) == pytest.approx(4.0, abs=1e-6)
    # scaling N(0,I) by 2: FID = sum over dims of (1 + 4 - 2*2) = 4 (up to sampling noise)
    y = rng.standard_normal((20000, 4))
    assert fid(rng.standard_normal((20000, 4)), 2 * y) == pytest.approx(4.0, abs=0.3)
