"""tools/judge_neighbours.py: a motion's nearest references under the TMA judge, its own take left out."""
import numpy as np
from tool_module import load_tool

from shapemove.core.eval.action_classifier import ActionClassifier


def test_nearest_references_leave_out_the_motions_own_take():
    ids = ["cmu_105_03", "cmu_105_03_mirror", "cmu_105_04", "cmu_08_05", "cmu_07_05", "cmu_02_01"]
    labels = ["walk in a figure eight", "walk in a figure eight", "walk in a figure eight", "walk", "walk", "run"]
    angles = np.radians([0.0, 2.0, 10.0, 30.0, 40.0, 90.0])
    emb = np.stack([np.cos(angles), np.sin(angles)], 1)
    judge = ActionClassifier(emb, labels, k=3, sources=ids)
    judge.ids = ids
    tool = load_tool("judge_neighbours")
    vote, near = tool.neighbours(judge, np.array([1.0, 0.0]), [], k=3)
    assert vote == "walk in a figure eight" and [c for _, c, _ in near] == ids[:3]
    assert abs(near[2][2] - np.cos(np.radians(10.0))) < 1e-6
    vote, near = tool.neighbours(judge, np.array([1.0, 0.0]), ["cmu_105_03"], k=3)   # the take and its mirror out
    assert [c for _, c, _ in near] == ["cmu_105_04", "cmu_08_05", "cmu_07_05"] and vote == "walk"
