"""Travel the words name: "forward", "backwards", "steps back", "in place", "steps to the left",
"moves sideways".

Best of N (``rerank.CandidatePicker``) compares candidates with the prompt through the TMA, which
reads what the body does, not which way it goes: for "a tall heavy man trudges forward" it chose
a captured walk backward that memory retrieval had offered. A candidate whose root travel
contradicts the travel words is therefore set aside before choosing, unless every candidate does.

The root travel is read from the features' own root velocities (``features.py``: metres per frame
in the root frame, +Z forward, +X the body's left), summed over the clip, so a walk that curves
still counts as forward. A word only rules out what goes against it by more than ``SLACK``
metres: "punches forward" does not ask a punch to travel, it refuses one that walks backward.
Both ways named ("forward and back", "left and right") is no direction at all.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

SLACK = 0.5  # metres of travel against the words that are tolerated (a sway, a step to balance)

_FORWARD = re.compile(r"\b(forwards?|ahead|onwards?|toward(?:s)? (?:the )?(?:camera|viewer))\b", re.I)
_BACKWARD = re.compile(r"\b(backwards?|in reverse|backs? (?:up|away)|backing (?:up|away)|retreat\w*|"
                       r"(?:steps?|stepping) back(?! and forth))\b", re.I)
_IN_PLACE = re.compile(r"\b(in place|on the spot)\b", re.I)
# a side named for travel: a verb of going, then within three words "to the left" / "to his right"
_GOING = r"\b(?:steps?|stepping|shuffl\w*|walk\w*|mov\w*|slid\w*|glid\w*|crab\w*|strafe\w*|side-?step\w*|run\w*|jog\w*|hop\w*|go(?:es|ing)?)\b"
_SIDE = re.compile(_GOING + r"(?:\W+\w+){0,3}?\W+(?:to|towards?|over to) (?:the|his|her|their|its|your) (left|right)\b", re.I)
_SIDEWAYS = re.compile(_GOING + r"(?:\W+\w+){0,3}?\W+(sideways|sidewards)\b", re.I)


@dataclass(frozen=True)
class Travel:
    """Which way the words send the body: ``forward`` +1 / -1 (backward) / 0, ``side`` +1 (left) /
    -1 (right) / 0, ``sideways`` (either side, more than forward), ``in_place``."""
    forward: int = 0
    side: int = 0
    sideways: bool = False
    in_place: bool = False

    @property
    def named(self) -> bool:
        return bool(self.forward or self.side or self.sideways or self.in_place)


def travel_of(prompt: str) -> Travel:
    """The travel ``prompt`` names (nothing for a prompt that names none or contradicts itself)."""
    fw, bw = bool(_FORWARD.search(prompt)), bool(_BACKWARD.search(prompt))
    sides = {m.group(1).lower() for m in _SIDE.finditer(prompt)}
    return Travel(forward=(fw and not bw) - (bw and not fw),
                  side=int(sides == {"left"}) - int(sides == {"right"}),
                  sideways=bool(_SIDEWAYS.search(prompt)) and not sides,
                  in_place=bool(_IN_PLACE.search(prompt)))


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
    if travel.in_place and np.hypot(fwd, left) > 2 * slack:
        return False
    return True


def allowed(prompt: str, feats: list) -> np.ndarray:
    """(N,) bool: the candidates that obey the prompt's travel words; all of them where none does
    (the words are then no help in choosing) or the prompt names no travel."""
    travel = travel_of(prompt)
    ok = np.array([obeys(travel, f) for f in feats], dtype=bool) if travel.named else np.ones(len(feats), bool)
    return ok if ok.any() else np.ones(len(feats), bool)
