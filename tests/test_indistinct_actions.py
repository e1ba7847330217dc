"""Pairs of actions a judge does not tell apart in real windows (core/eval/indistinct_actions.py).

The references are whole takes; a wave take is mostly waving with a short raise at its start, so its
later windows look like a raised hand's. Embeddings are two pooled feature columns, worked by hand:
a wave take (col0 = 1, col1 = 1 on its first 20 of 160 frames) pools to (1, 0.125); its windows at
frames 40 and 80 pool to (1, 0), a raised hand's exactly; its window at 0 to (1, 0.25), nearest the
other waves (cosine 0.996 against 0.970).
"""
import numpy as np
import pytest

from shapemove.core.eval.action_classifier import FEATURES, ActionClassifier
from shapemove.core.eval.indistinct_actions import (indistinct_pairs, merged_right, take_counts,
                                                    window_accuracy, window_confusion)
from shapemove.core.eval.paraphrase_eval import _tally


def _embed(feats):
    return np.stack([[f[:, 0].mean(), f[:, 1].mean()] for f in feats]).astype(np.float32)


def _feats(frames, col0, col1_first=0, col1=0.0):
    f = np.zeros((frames, 263), np.float32)
    f[:, 0] = col0
    f[:, 1] = col1
    f[:col1_first, 1] = 1.0
    return f


@pytest.fixture
def judged(tmp_path):
    takes = {}
    for i in range(4):
        takes[f"wave_{i}"] = ("wave", _feats(160, 1.0, col1_first=20))
    for i in range(3):
        takes[f"raise_{i}"] = ("raise hand", _feats(100, 1.0))
        takes[f"kick_{i}"] = ("kick", _feats(90, 0.0, col1=1.0))
    for i in range(2):   # two takes only: read as kicks, never merged
        takes[f"jump_{i}"] = ("jump", _feats(90, 0.3, col1=1.0))
    takes["wave_0_mirror"] = takes["wave_0"]   # a copy of a take: never its own window's reference
    (tmp_path / FEATURES).mkdir()
    for cid, (_, f) in takes.items():
        np.save(tmp_path / FEATURES / f"{cid}.npy", f)
    ids = list(takes)
    labels = [takes[c][0] for c in ids]
    clf = ActionClassifier(_embed([takes[c][1] for c in ids]), labels, _embed, k=3,
                           sources=[c.removesuffix("_mirror") for c in ids])
    clf.ids = ids
    return clf, tmp_path


def test_wave_windows_read_as_raised_hands_make_a_pair(judged):
    clf, data = judged
    conf = window_confusion(clf, data, frames=80)
    assert conf["wave"] == {"wave": 4, "raise hand": 8}     # windows at 0 / 40 / 80 of each of 4 takes
    assert conf["raise hand"] == {"raise hand": 3}          # a 100-frame take: one window, at 0
    assert conf["kick"] == {"kick": 3}
    assert conf["jump"] == {"kick": 2}
    takes = take_counts(clf)
    assert takes == {"jump": 2, "kick": 3, "raise hand": 3, "wave": 4}
    pairs = indistinct_pairs(conf, takes)
    assert pairs == {frozenset({"wave", "raise hand"})}     # jump -> kick: 2 takes, reported only
    assert indistinct_pairs(conf, takes, min_takes=2) == {frozenset({"wave", "raise hand"}), frozenset({"jump", "kick"})}
    assert indistinct_pairs(conf, takes, share=0.7) == set()   # 8 of 12 wave windows
    acc = window_accuracy(conf, pairs)
    assert acc["wave"] == 1.0 and acc["jump"] == 0.0
    assert window_accuracy(conf)["wave"] == pytest.approx(4 / 12)


def test_merged_counts_the_pair_both_ways_and_nothing_else():
    pairs = {frozenset({"wave", "raise hand"})}
    assert merged_right("wave", "raise hand", pairs) and merged_right("raise hand", "wave", pairs)
    assert not merged_right("wave", "kick", pairs)
    rows = [{"action": "wave", "also": [], "p": "raise hand"}, {"action": "wave", "also": [], "p": "wave"},
            {"action": "kick", "also": ["punch"], "p": "punch"}, {"action": "kick", "also": [], "p": "wave"}]
    t = _tally(rows, "p", pairs)
    assert t["accuracy"] == 0.25 and t["accuracy_lenient"] == 0.5 and t["accuracy_merged"] == 0.5
    assert t["per_action"]["wave"]["accuracy_merged"] == 1.0 and t["per_action"]["kick"]["accuracy_merged"] == 0.0
    assert "accuracy_merged" not in _tally(rows, "p")
