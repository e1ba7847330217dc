"""A change of posture the words ask for is made: "gets up" rises from low, "lies down" and "sits
down" end low.

The TMA that chooses among the candidates (``rerank``) reads the words that say who moves and how
as readily as the action: for "an old man gets up" it scored a sample of an old man standing
still 0.74 and DeepMimic's captured get-ups from the floor 0.24 and 0.15 (each credited 0.3 as a
take of the asked action), so the man stood for 3 s. A change of posture is plain in the root's
height, so when the plan's action is one (``plan/vocabulary.POSTURE_CHANGES``, with the way the
root goes), the candidates that make it are the ones that compete: the root's height at the end
against the start, as a share of the candidate's highest root, moves by at least ``MIN_CHANGE``
the way the action goes (the built data's get-ups and lie-downs move 0.7 of it; its walks at most
0.2). When no candidate makes it, all compete.

A sitting body keeps its head up and a lying one does not, though both bring the root as low (a
sit on the floor): "a person sits down" chose a sample that lay on the floor, head 0.3 m high. So
for a sit the candidates whose head stays up compete, and for a lie-down those whose head goes
down: the head's low height (its ``LOW_QUANTILE``) under ``LYING`` of its highest lies (the built
data's lie-downs 0.08-0.09, get-ups from the floor 0.09-0.28, squats 0.54-0.73, bends 0.52); a sit
with none whose head stays up keeps a candidate that does not lie rather than one that does ("no
sit is better than a body lying on the floor"). Of a sit's, the ones that start standing are kept
when any does (``starts_standing``): a 3 s segment "sits down" chose the last 3 s of a lie-down's
codes, which start in a crouch. Not of a lie-down's: asked for 4 s, the captured lie-downs' last
4 s start kneeling and end lying flat (the head 0.13 m high), while the samples that start standing
end half-way, the head 0.35-0.48 m high; a lie-down must end lying.

    keep = posture_kept("get up", feats, keep)     # (N,) bool among (T, 263) candidates
"""
from __future__ import annotations

import numpy as np

from ..body.skeleton import JOINT_NAMES
from ..motion.features import height_column
from ..plan.vocabulary import POSTURE_CHANGES

MIN_CHANGE = 0.3   # of the candidate's highest root
ENDS = 5           # frames averaged at the start and at the end
LYING = 0.35       # a head whose low height is under this share of its highest lies
LOW_QUANTILE = 0.1
# the head's height in the (T, 263) features: its y in ``ric`` (joints 1..21, heights the floor's)
HEAD_Y = height_column(JOINT_NAMES.index("head"))
HEAD_DOWN = {"lie down": True, "sit": False}   # where the head goes in the change of posture
STANDING = 0.95    # a root this share of the leg's length high stands (standing: 1.05-1.15)


def posture_change(features) -> float:
    """The root's height at the end minus at the start of a (T, 263) candidate, as a share of its
    highest root."""
    return height_change(np.asarray(features, dtype=np.float64)[:, 3])


def height_change(y) -> float:
    """A (T,) height at the end (its last ``ENDS`` frames) minus at the start, as a share of its highest."""
    y = np.asarray(y, dtype=np.float64)
    return float((y[-ENDS:].mean() - y[:ENDS].mean()) / max(y.max(), 1e-6))


def lies(features) -> bool:
    """Whether a (T, 263) candidate lies on the floor: its head's low height under ``LYING`` of its
    highest (module doc)."""
    head = np.asarray(features, dtype=np.float64)[:, HEAD_Y]
    return bool(np.quantile(head, LOW_QUANTILE) < LYING * max(head.max(), 1e-6))


def posture_kept(action: str | None, feats: list, keep: np.ndarray) -> np.ndarray:
    """``keep`` narrowed to the candidates that make ``action``'s change of posture, when it is one
    and any of them makes it; for a sit or a lie-down, with the head where that posture has it
    (module doc)."""
    way = POSTURE_CHANGES.get(action or "")
    if way is None:
        return keep
    makes = np.array([way * posture_change(f) >= MIN_CHANGE for f in feats]) & keep
    if action in HEAD_DOWN:
        head = np.array([lies(f) for f in feats]) == HEAD_DOWN[action]
        up = np.array([starts_standing(f) for f in feats]) if action == "sit" else np.ones(len(feats), bool)
        for narrowed in (makes & head & up, makes & head, keep & head):
            if narrowed.any():
                return narrowed
    return makes if makes.any() else keep


def starts_standing(features) -> bool:
    """Whether a (T, 263) candidate starts standing: its root at the start at least ``STANDING`` of
    the leg's length (hip to knee to ankle, its first frame), where a body already going down (a
    lie-down's last seconds: 0.7 of it) is lower."""
    from ..motion.features import joints_from_features
    from ..motion.skeleton_ops import leg_length

    f = np.asarray(features, dtype=np.float32)[:ENDS]
    return bool(f[:, 3].mean() >= STANDING * leg_length(joints_from_features(f)))
