"""Action balance: a clip's sampling weight in training, so an action's share of training does not
follow its clip count (thousands of Bandai hand raises against five cartwheels). Used by the T5's
examples (``t5_dataset``) and the SA-VAE's batches (``motion_dataset.BatchStream``); a mirror,
shape-augmented or composed clip counts as the action of its labels like any other."""
from __future__ import annotations

import numpy as np


def clip_weights(ids: list[str], labels: dict, balance: float) -> np.ndarray:
    """Sampling weight per clip: 1 / (clips sharing its main action) ** ``balance``. 0 draws every
    clip equally (common actions dominate); 1 draws every action equally, then a clip of it.
    ``labels``: {clip id: its stored labels ({"actions": [main, ...]})}; a clip without one counts
    with the others that have none."""
    main = [((labels.get(c) or {}).get("actions") or [""])[0] for c in ids]
    count: dict[str, int] = {}
    for a in main:
        count[a] = count.get(a, 0) + 1
    return np.array([count[a] ** -float(balance) for a in main], dtype=np.float64)


def dataset_weights(root, ids: list[str], balance: float) -> np.ndarray:
    """``clip_weights`` of a built dataset's clips, their labels read from its meta."""
    from ..data.actions import stored_labels

    return clip_weights(ids, {c: stored_labels(root, c) for c in ids}, balance)
