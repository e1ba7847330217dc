"""Where a training crop starts: uniformly in the clip, or where the body moves.

A take often opens and closes standing still, and a kick is a second of a ten-second clip: crops
drawn uniformly see the standing more than the kick. ``start_weights`` weighs every possible start
of a ``window``-frame crop by how far the root-relative joints move inside it (the HumanML3D
``ric`` channels, so walking in a straight line counts its swinging legs, not its travel), mixed
with the uniform draw by ``share`` (0: uniform, 1: in proportion to the movement alone)."""
from __future__ import annotations

import numpy as np

from ..motion.features import feature_slices

FLOOR = 0.05   # a start's weight never drops below this fraction of the clip's mean (a still crop stays possible)


def pose_motion(features: np.ndarray) -> np.ndarray:
    """(T,) metres the 21 root-relative joints move (summed) from each frame to the next, of (T,263)
    features; the last frame repeats the one before it."""
    ric = np.asarray(features[:, feature_slices["ric"]], dtype=np.float32).reshape(len(features), -1, 3)
    if len(ric) < 2:
        return np.zeros(len(ric), np.float32)
    step = np.linalg.norm(np.diff(ric, axis=0), axis=-1).sum(axis=1)
    return np.append(step, step[-1]).astype(np.float32)


def start_weights(features: np.ndarray, window: int, share: float) -> np.ndarray:
    """(T - window + 1,) sampling weight of each crop start of (T,263) ``features``, mean 1."""
    n = len(features) - window + 1
    if n < 1:
        raise ValueError(f"clip of {len(features)} frames is shorter than the {window}-frame window")
    if share <= 0:
        return np.ones(n, np.float64)
    c = np.concatenate([[0.0], np.cumsum(pose_motion(features), dtype=np.float64)])
    moved = (c[window:window + n] - c[:n]) / window           # mean movement per frame inside each crop
    moved = moved / moved.mean() if moved.mean() > 0 else np.ones(n)
    w = (1 - share) + share * np.maximum(moved, FLOOR)
    return w / w.mean()
