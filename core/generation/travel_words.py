"""Travel the words name: "forward", "backwards", "steps back", "in place", "steps to the left",
"moves sideways".

Best of N (``rerank.CandidatePicker``) compares candidates with the prompt through the TMA, which
reads what the body does, not which way it goes: for "a tall heavy man trudges forward" it chose
a captured walk backward that memory retrieval had offered. A candidate whose root travel
contradicts the travel words is therefore set aside before choosing, unless every candidate does.

The root travel is read from the features' own root velocities (``features.py``: metres per frame
in the root frame, +Z forward, +X the body's left), summed over the clip, so a walk that curves
still counts as forward. A word only rules out what goes against it by more than ``SLACK``
metres: "punches forward" does not ask a punch to travel, it refuses one that walks backward; "in
place" refuses more than ``SLACK`` metres of travel any way (a hop of a metre forward for "hops on
the spot").
A captured take that goes to the other side than the words name is offered as its mirror image
(``other_side``; not where a hand or a foot is named, which its own side decides). The words are read
by the plan (``plan/reader.travel_of``). Both ways named ("forward and back", "left and right") is no direction at all.
A gait other than a walk asked backwards ("runs backwards") has the walk backward's captured takes
offered (``backward_taken``): the data hold no other gait going backwards.
"""
from __future__ import annotations

import numpy as np

from ..plan.reader import TRAVEL_WAYS, Travel

SLACK = 0.5  # metres of travel against the words that are tolerated (a sway, a step to balance)

def body_frame_travel(features: np.ndarray) -> tuple[float, float]:
    """(forward, left) metres the root goes over a (T, 263) feature clip, each frame's step in its
    own root frame."""
    f = np.asarray(features, dtype=np.float64)
    return float(f[:, 2].sum()), float(f[:, 1].sum())


def obeys(travel: Travel, features: np.ndarray, slack: float = SLACK) -> bool:
    """False where the clip's root travel goes against ``travel`` by more than ``slack`` metres."""
    fwd, left = body_frame_travel(features)
    if travel.forward and travel.forward * fwd < -slack:
        return False
    if travel.side and travel.side * left < slack:
        return False
    if travel.sideways and (abs(left) < slack or abs(left) < abs(fwd)):
        return False
    if travel.in_place and np.hypot(fwd, left) > slack:
        return False
    return True


def other_side(travel: Travel, features: np.ndarray, slack: float = SLACK) -> bool:
    """Whether a clip goes to the other side than ``travel`` names by more than ``slack`` metres:
    its mirror image goes the side asked ("a woman does a cartwheel to the right": the captured
    cartwheel goes 0.9 m to its left)."""
    return bool(travel.side) and travel.side * body_frame_travel(features)[1] < -slack


def allowed(travel: Travel, feats: list) -> np.ndarray:
    """(N,) bool: the candidates that obey the plan's ``travel`` (``plan.reader.Travel``); all of them
    where none does (the words are then no help in choosing) or it names no travel."""
    ok = np.array([obeys(travel, f) for f in feats], dtype=bool) if travel.named else np.ones(len(feats), bool)
    return ok if ok.any() else np.ones(len(feats), bool)


SIDEWAYS_ACTIONS = frozenset({"sidestep"})   # actions that go to the side by what they are


def goes_sideways(features: np.ndarray) -> bool:
    """Whether a clip goes to the side at least as far as forward (and more than ``SLACK``): what
    "moves sideways" asks (``obeys``), and what a sidestep's captured take must do to compete where
    any does (the data's are Bandai's walks to the left or right, most going forward two to four
    times as far as to the side: "a man steps to the side" walked ahead, veering)."""
    return obeys(TRAVEL_WAYS["sideways"], features)


BACKWARD_GAIT = "walk backward"   # the data's one gait that goes backwards


def backward_taken(words, asked: str | None) -> str | None:
    """The action whose captured takes compete for a gait the words (``plan.words.Words``) send
    backwards: the walk backward for any other gait of ``vocabulary.GAITS`` ("runs backwards",
    "jogs backwards": no capture does either, and every take and sample goes forward, so the run
    went 7.5 m forward and the jog stood about); None otherwise."""
    from ..plan.vocabulary import GAITS

    if asked is None or asked == BACKWARD_GAIT or asked not in GAITS or words.travel.forward >= 0:
        return None
    return BACKWARD_GAIT
