"""A gesture made with the hands the words ask: one hand, or both.

The built-in library's waves and raised hands are Bandai's one-hand takes (left, right) and
both-hands takes, and its captions give the both-hands takes plain captions too ("A man waves."):
for "lifts one hand high" or "raises a hand" the nearest takes by caption could be both-hands
ones. So where the words ask a gesture of the hands (``HAND_GESTURES``: a wave, a wave goodbye, a
raised hand, a beckon, a guiding gesture) and say one hand ("a hand", "one arm", a named side) or
both ("both hands", "her hands", "his arms"; ``plan.words.Words.hands``), only the captured takes
made that way are offered when any is (the takes nearest by caption,
``captured_takes.TakePool.nearest``). Where the words say neither ("a man waves"), every take
competes: the judges read the library's one-hand waves as raised hands (blind paraphrases: waves
60 -> 20 % by the TMA judge when one hand was made the default; docs/design-notes.md). A take is
made with both when its less active hand travels at least ``BOTH_SHARE`` of the more active one's
path (``part_compose.side_activity``, wrist and elbow relative to the pelvis): Bandai's both-hands
waves and raises 0.78-1.00, its one-hand ones 0.05-0.33 (whole takes). Whatever the action, when
the words say both hands the candidates made with both are the ones that compete, when any is
(``both_kept``, in ``rerank``): the choice had kept a sample stretching one arm up for "stretches
both arms above the head".
"""
from __future__ import annotations

from ..data.actions import ACTIONS
from ..data.compose_parts import ARMS_ACTIONS

BOTH_SHARE = 0.6
# the gestures of the hands: the vocabulary's gestures an arm makes (not a bow, a wash)
HAND_GESTURES = frozenset(a for a in ARMS_ACTIONS if a in ACTIONS and ACTIONS[a].group == "gesture")


def made_with_both(joints) -> bool:
    """Whether (T, 22, 3) ``joints`` make their gesture with both hands (module docstring)."""
    from .part_compose import side_activity

    left, right = side_activity(joints, "hand")
    return min(left, right) >= BOTH_SHARE * max(left, right, 1e-6)


def both_kept(words, feats: list, keep):
    """``keep`` (N,) narrowed to the candidates made with both hands when the words (``plan.words.Words``)
    say both ("stretches both arms above the head": a sample raising one arm was chosen) and any of
    them is; ``keep`` itself otherwise. ``feats``: (T, 263) candidates."""
    import numpy as np

    from ..motion.features import joints_from_features

    if words is None or words.hands != "both":
        return keep
    both = np.array([made_with_both(np.asarray(joints_from_features(f))) for f in feats]) & keep
    return both if both.any() else keep


def hands_wanted(words, asked: str | None) -> bool | None:
    """For a gesture of the hands the words (``plan.words.Words``) ask: True when they say both hands,
    False when one; None when they say neither or ``asked`` is no such gesture (any take competes)."""
    if words is None or asked not in HAND_GESTURES or words.hands is None:
        return None
    return words.hands == "both"
