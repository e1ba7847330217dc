from __future__ import annotations

import numpy as np

from shapemove.core.generation.floor_sit import LOW, SETTLED, UPRIGHT, sit_end, sitting
from shapemove.core.motion.skeleton_ops import leg_length


def _lie_down(root_y, head_y):
    """(T, 22, 3) joints: the pelvis and head at those heights, the hips at the pelvis's, the knees
    0.4 m ahead of them, the ankles and feet on the floor under the knees (a leg 0.4 m + the
    pelvis's height long)."""
    j = np.zeros((len(root_y), 22, 3))
    j[:, 0, 1], j[:, 15, 1] = root_y, head_y
    for hip, knee, ankle, foot, x in ((1, 4, 7, 10, 0.1), (2, 5, 8, 11, -0.1)):
        j[:, hip] = np.stack([np.full(len(j), x), j[:, 0, 1], np.zeros(len(j))], 1)
        j[:, knee] = j[:, hip] + [0.0, 0.0, 0.4]
        j[:, ankle] = j[:, foot] = np.stack([np.full(len(j), x), np.zeros(len(j)), np.full(len(j), 0.4)], 1)
    return j


def test_a_lie_down_sits_where_the_pelvis_is_low_and_the_trunk_up():
    """Standing (pelvis 0.9, head 1.5: trunk 0.6), going down, sitting (pelvis 0.3 -> 0.15 -> 0.18,
    head 0.8), leaning back, lying (head 0.15). Frames 0-4 stand, 5-6 go down; 7-11 sit (pelvis
    under LOW x 0.9 = 0.315, head above the pelvis by at least UPRIGHT x 0.6 = 0.45); frame 12 leans
    back (0.55 - 0.2 = 0.35 < 0.45); the sit ends where its pelvis is lowest (frame 10)."""
    root = [0.9] * 5 + [0.7, 0.45] + [0.3, 0.25, 0.2, 0.15, 0.18] + [0.2, 0.2, 0.2]
    head = [1.5] * 5 + [1.3, 1.0] + [0.8, 0.78, 0.75, 0.72, 0.7] + [0.55, 0.15, 0.15]
    assert LOW * 0.9 == 0.315 and abs(UPRIGHT * 0.6 - 0.45) < 1e-12
    j = _lie_down(root, head)
    assert np.flatnonzero(sitting(j)).tolist() == [7, 8, 9, 10, 11]
    assert sit_end(j) == 11                      # frames 0..10 played, frame 10 held
    up = j.copy()
    up[10, [7, 8, 10, 11], 1] = 0.2                 # the feet 0.2 m up where it sits: not settled
    assert leg_length(up) < 1.2 and 0.2 > SETTLED * leg_length(up) and sit_end(up) is None
    j[7:12, 15, 1] = 0.4                         # the head never up while low: it never sits
    assert sit_end(j) is None


def test_only_the_first_sitting_stretch_counts():
    """A take that sits, stands and sits again plays to its first sit."""
    root = [0.9] * 3 + [0.2, 0.1, 0.2] + [0.9] * 2 + [0.05, 0.05]
    head = [1.5] * 3 + [0.8, 0.75, 0.8] + [1.5] * 2 + [0.7, 0.7]
    assert sit_end(_lie_down(root, head)) == 5
