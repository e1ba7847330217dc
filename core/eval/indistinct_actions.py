"""Actions a judge does not tell apart in real performances: the pairs merged for the bars.

A judge (``action_classifier.ActionClassifier``) reads a generated motion as long as the product
plays it (4 s), while its references are whole takes. Cut to that length, real takes of some actions
read as another one: under the TMA judge, 4 s of a captured wave read as a raised hand 96 % of the
time (the whole take, raised, waved and lowered, reads right), and real jumps in place read as jumps
forward. Here every reference take's windows of the played length are judged among the other takes
(never their own: the clip, its mirror image, its augmented copies), and where the judge names real
windows of an action ``a`` as ``b`` at least ``SHARE`` of the time, ``a`` having at least
``MIN_TAKES`` takes, the pair {a, b} is one the judge does not tell apart. The evaluations report a
``merged`` figure beside the strict one: a motion of either action read as the other counts.

    conf = window_confusion(classifier, "data/built", frames=80)   # {action: {named: windows}}
    pairs = indistinct_pairs(conf, take_counts(classifier))         # {frozenset({"wave", "raise hand"}), ...}
    merged_right("wave", "raise hand", pairs)                       # True
"""
from __future__ import annotations

import numpy as np

SHARE = 0.25            # a real window of a named b this often: {a, b} not told apart
MIN_TAKES = 3           # actions with fewer takes are reported, not merged
TAKES_PER_ACTION = 40   # takes of a frequent action judged (a seeded draw)
WINDOWS_PER_TAKE = 6    # windows of a long take, every half window from its start


def take_counts(classifier) -> dict[str, int]:
    """{action: captured takes among the judge's references} (mirror images and augmented copies
    count with their take)."""
    from ..models.motion_memory import take_of

    takes: dict[str, set] = {}
    for a, s in zip(classifier.labels, classifier.sources):
        takes.setdefault(a, set()).add(take_of(s))
    return {a: len(v) for a, v in sorted(takes.items())}


def window_confusion(classifier, data, frames: int, seed: int = 0) -> dict[str, dict[str, int]]:
    """{action: {action named: windows}}: each reference take (one clip of it, at most
    ``TAKES_PER_ACTION`` a action, drawn by ``seed``) cut into windows of ``frames`` frames (a shorter
    take whole), each judged by ``classifier`` without its own take."""
    from ..models.motion_memory import take_of
    from .action_classifier import load_features

    ids = getattr(classifier, "ids", None)
    if not ids:
        return {}
    first: dict[str, tuple[str, str]] = {}
    for cid, a in zip(ids, classifier.labels):
        first.setdefault(take_of(cid), (cid, a))
    by_action: dict[str, list[str]] = {}
    for cid, a in first.values():
        by_action.setdefault(a, []).append(cid)
    rng = np.random.default_rng(seed)
    frames = max(4, int(frames))
    feats, labels, own = [], [], []
    for a, cids in sorted(by_action.items()):
        if len(cids) > TAKES_PER_ACTION:
            cids = [cids[i] for i in np.sort(rng.choice(len(cids), TAKES_PER_ACTION, replace=False))]
        for cid in cids:
            f = load_features(data, cid)
            if f is None:
                continue
            starts = range(0, max(1, len(f) - frames + 1), max(1, frames // 2))
            for s in list(starts)[:WINDOWS_PER_TAKE]:
                feats.append(f[s:s + frames])
                labels.append(a)
                own.append(cid)
    conf: dict[str, dict[str, int]] = {}
    for a, p in zip(labels, classifier.classify(feats, exclude=own) if feats else []):
        row = conf.setdefault(a, {})
        row[p] = row.get(p, 0) + 1
    return conf


def indistinct_pairs(confusion: dict, takes: dict[str, int], share: float = SHARE,
                     min_takes: int = MIN_TAKES) -> set[frozenset]:
    """The pairs {a, b} whose real windows the judge does not tell apart: windows of ``a`` (an action
    with at least ``min_takes`` takes) named ``b`` at least ``share`` of the time."""
    pairs = set()
    for a, row in confusion.items():
        n = sum(row.values())
        if takes.get(a, 0) < min_takes or not n:
            continue
        pairs |= {frozenset((a, b)) for b, m in row.items() if b != a and m / n >= share}
    return pairs


def merged_right(expected: str, named: str, pairs: set[frozenset]) -> bool:
    """The action named counts for the one expected: the same, or a pair the judge does not tell apart."""
    return named == expected or frozenset((expected, named)) in pairs


def window_accuracy(confusion: dict, pairs: set[frozenset] | None = None) -> dict[str, float]:
    """{action: share of its real windows named right} (merged with ``pairs`` when given)."""
    out = {}
    for a, row in confusion.items():
        n = sum(row.values())
        out[a] = sum(m for b, m in row.items() if merged_right(a, b, pairs or set())) / n if n else 0.0
    return dict(sorted(out.items()))
