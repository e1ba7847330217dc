"""A gesture made with the hands the words ask: one hand, unless they say both.

The built-in library's waves are Bandai's one-hand waves (left, right) and both-hands waves, and
its captions give the both-hands takes the plain "A man waves." too: for "a man waves" they were
the five nearest by caption (0.95-0.98 against 0.46-0.52), and on seeds 0-5 the body waved both
arms over its head every time. People asked to wave wave a hand. So where the words ask a gesture
of the hands (``HAND_GESTURES``: a wave, a wave goodbye, a raised hand, a beckon, a guiding
gesture) and do not say both hands or arms (``plan.words.Words.both_hands``: "waves with both
hands", "raises her hands"), a captured take made with both hands is not offered when one made
with one hand is (the takes nearest by caption, ``captured_takes.TakePool.nearest``); where they
say both, the other way round. A take is made with both when its less active hand travels at
least ``BOTH_SHARE`` of the more active one's path (``part_judge.side_activity``, wrist and elbow
relative to the pelvis): Bandai's both-hands waves and raises 0.81-1.00, its one-hand ones
0.02-0.40.
"""
from __future__ import annotations

from ..data.actions import ACTIONS
from ..data.compose_parts import ARMS_ACTIONS

BOTH_SHARE = 0.6
# the gestures of the hands: the vocabulary's gestures an arm makes (not a bow, a wash)
HAND_GESTURES = frozenset(a for a in ARMS_ACTIONS if a in ACTIONS and ACTIONS[a].group == "gesture")


def made_with_both(joints) -> bool:
    """Whether (T, 22, 3) ``joints`` make their gesture with both hands (module docstring)."""
    from ..eval.part_judge import side_activity

    left, right = side_activity(joints, "hand")
    return min(left, right) >= BOTH_SHARE * max(left, right, 1e-6)


def hands_wanted(words, asked: str | None) -> bool | None:
    """For a gesture the words (``plan.words.Words``) ask: True when they say both hands, False for
    one; None when ``asked`` is no gesture (any take competes)."""
    if words is None or asked not in HAND_GESTURES:
        return None
    return bool(words.both_hands)
