"""Judge a motion by body part: what the legs and root do, what the arms do, which side moves most.

    judge = PartJudge.from_data("data/built")      # the train split's real captured clips, once
    judge.judge([features, ...])   # [{"legs": "jog", "path": "straight", "arms": "wave", "hand_side": "left", ...}]
    real_accuracy(judge, "data/built", "test")      # how often it is right on real held-out clips

No learned model: hand-made descriptors of the joints (``joints_from_features`` of the (T, 263)
HumanML3D features, 20 fps) and the nearest real clips, so the generator's TMA, which picks among
its samples (``generation/rerank.py``), cannot flatter it (as ``action_classifier.FeatureEmbedder``).

- **legs** (legs and root only): root velocity in the body's own frame (forward, sideways, up
  and down) and its direction, pelvis height, the knees, ankles and feet relative to the pelvis in
  the body's frame (mean and spread over time), foot speeds, the share of frames with both feet off
  the floor and the stride frequency; every length in leg lengths, so bodies of any size compare.
  Not the hips, whose place is the skeleton's (a take posed on a body with hips 6 % wider, relative
  to its legs, moved them 6 standard deviations of the references'), and across the body the legs
  are placed about their own middle: a circling gait leans into its turn, a straight one does not.
  Nothing of the path: a gait reads the same circling or straight (the captured jogs at a jog's
  pace are HDM05's, all circling left, played straight for "jogs forward"). Classes: the gaits of
  ``compose_parts.LEGS_ACTIONS`` ("walk in a circle" is a walk: its gait) and ``STAND`` (the real
  standing gesture clips). A locomotion reference is also matched by its steady stretch
  (``steady_span``: the pelvis at its cruising speed, without the start from standing or the
  stop), as a gait played on from a loop is steady: HDM05's jogs are 4 steps from standing.
  ``part_judge_check.py`` in ``tools/`` measures what each of these does on real clips. ``path``
  is read apart from the gait: ``CIRCLE`` when the body keeps turning one way while it moves (each
  quarter of the clip turns >= ``CIRCLE_DEG_PER_S`` the same way), else "straight".
- **arms** (``ARMS``): collars, shoulders, elbows and wrists relative to the chest (spine3) in the
  body's frame, in arm lengths: mean, spread and range over time, wrist and elbow speeds, the
  wrists' highest point and their dominant frequency. Classes: the gestures of
  ``compose_parts.ARMS_ACTIONS`` from real clips whose body stands (no locomotion among their
  actions), and ``NO_GESTURE`` (the arms of the real locomotion clips: they swing or hang).
  "wave goodbye" is judged as "wave": the same motion of the hand (``SAME_MOTION``).
- **side**: the path length of the wrist and elbow (``hand``) or of the ankle and foot (``foot``)
  relative to the pelvis in the body's frame (SMPL: the body's left at +X when it faces +Z), left
  against right: the larger names the side that moves most.

Both k-NN readings are side-invariant: every reference clip is also matched as its mirror image
(``data/mirror.py``'s ``mirror_joints``), with the same label. A class's score is the mean distance
to its ``k`` nearest references (class-balanced: a class of 4 clips is not outvoted by one of
1000); each descriptor group counts equally (z-scored by the references' spread, divided by the
square root of its size), except the root's velocity for the legs, which counts double
(``LEGS_WEIGHTS``). References are the real captured clips of a split (not the
shape-augmented, mirrored or composed copies), at most ``max_per_class`` source clips per class.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..body.skeleton import FACE_JOINTS
from ..constants import FPS
from ..data.actions import ACTIONS
from ..data.built_meta import is_real
from ..data.compose_parts import ARMS_ACTIONS, LEGS_ACTIONS
from ..data.mirror import mirror_joints
from ..errors import ShapeMoveError
from ..geometry.rotations import yaw_matrix
from ..motion.features import FEATURE_DIM, joints_from_features
from ..motion.root_speed import steady_span
from ..motion.skeleton_ops import gaussian_smooth, heading_angles, leg_length, smooth_directions

STAND = "stand"
NO_GESTURE = "none"
CIRCLE = "walk in a circle"
STRAIGHT = "straight"
SAME_MOTION = {"wave goodbye": "wave"}
GAITS = tuple(a for a in LEGS_ACTIONS if a != CIRCLE) + (STAND,)
GESTURES = tuple(dict.fromkeys(SAME_MOTION.get(a, a) for a in ARMS_ACTIONS)) + (NO_GESTURE,)
CIRCLE_DEG_PER_S = 15.0      # each quarter of a circling clip turns at least this fast, one way
MOVING_LEGS_PER_S = 0.3      # ... while the pelvis moves at least this many leg lengths per second
MIN_FRAMES = 10
LEG_JOINTS = [1, 2, 4, 5, 7, 8, 10, 11]   # hips, knees, ankles, feet (left, right)
STRIDE_PAD = 256                           # samples the stride's spectrum is padded to: 0.08 Hz apart
ARM_JOINTS = [13, 14, 16, 17, 18, 19, 20, 21]
CHEST = 9
SIDE_JOINTS = {"hand": ([18, 20], [19, 21]), "foot": ([7, 10], [8, 11])}   # (left, right)
FEATURES = "new_joint_vecs"
LEGS_WEIGHTS = {"root": 2.0}  # how fast and which way the pelvis goes counts double


# -- the body's own frame -----------------------------------------------------------------------
def check_joints(joints) -> np.ndarray:
    j = np.asarray(joints, np.float64)
    if j.ndim != 3 or j.shape[1] < 22 or j.shape[2] != 3:
        raise ShapeMoveError(f"part judge: joints must be (frames, 22, 3), got shape {j.shape}")
    if len(j) < MIN_FRAMES:
        raise ShapeMoveError(f"part judge: a motion needs at least {MIN_FRAMES} frames, got {len(j)}")
    if not np.isfinite(j).all():
        raise ShapeMoveError("part judge: the joints hold NaN or infinite values")
    return j[:, :22]


def joints_of(features) -> np.ndarray:
    """(T, 263) HumanML3D features -> (T, 22, 3) joints (``joints_from_features``), checked."""
    f = np.asarray(features, np.float64)
    if f.ndim != 2 or f.shape[1] != FEATURE_DIM:
        raise ShapeMoveError(f"part judge: features must be (frames, {FEATURE_DIM}), got shape {f.shape}")
    if not np.isfinite(f).all():
        raise ShapeMoveError("part judge: the features hold NaN or infinite values")
    return check_joints(joints_from_features(f))


def headings(joints: np.ndarray, sigma: float = 2.0) -> np.ndarray:
    """(T,) yaw of the body's facing (hips + shoulders), lightly smoothed, unwrapped (radians)."""
    r_hip, l_hip, r_sh, l_sh = FACE_JOINTS
    across = (joints[:, r_hip] - joints[:, l_hip]) + (joints[:, r_sh] - joints[:, l_sh])
    fwd = np.stack([across[:, 2], np.zeros(len(joints)), -across[:, 0]], -1)
    norm = np.linalg.norm(fwd, axis=-1, keepdims=True)
    if (norm < 1e-9).any():
        raise ShapeMoveError("part judge: cannot tell which way the body faces (hips and shoulders coincide)")
    return np.unwrap(heading_angles(smooth_directions(fwd / norm, sigma)))


def body_frame(joints: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Joints relative to the pelvis's floor point, turned so each frame faces +Z (height kept)."""
    rel = joints.copy()
    rel[..., [0, 2]] -= joints[:, :1, [0, 2]]
    return np.einsum("tij,tkj->tki", yaw_matrix(-theta), rel)


def straight_joints(joints) -> np.ndarray:
    """The joints played off their path: each frame's pose as the body faces it, the pelvis moved by
    the same steps, taken along one heading (a circling take as a straight one)."""
    j = check_joints(joints)
    theta = headings(j)
    local = body_frame(j, theta)
    step = np.einsum("tij,tj->ti", yaw_matrix(-theta[:-1]), j[1:, 0] - j[:-1, 0])
    root = np.concatenate([np.zeros((1, 3)), np.cumsum(step, 0)])
    local[..., 0] += root[:, None, 0]
    local[..., 2] += root[:, None, 2]
    return local


def arm_length(joints: np.ndarray) -> float:
    seg = lambda a, b: np.linalg.norm(joints[:, a] - joints[:, b], axis=-1)  # noqa: E731
    return float(max(np.median((seg(16, 18) + seg(18, 20) + seg(17, 19) + seg(19, 21)) / 2), 1e-3))


def dominant_frequency(x: np.ndarray, pad: int = 64) -> tuple[float, float]:
    """(Hz, share of the power) of the strongest frequency in 0.3..5 Hz of a (T,) signal (0, 0 if
    flat), its spectrum zero-padded to at least ``pad`` samples. The share falls with the signal's
    length (a real walk's stride: 0.21, 0.39, 0.58 over 1, 2, 4 s), so the legs use the frequency only."""
    x = np.asarray(x, np.float64) - np.mean(x)
    n = max(len(x), pad)
    power = np.abs(np.fft.rfft(x * np.hanning(len(x)), n)) ** 2
    freq = np.fft.rfftfreq(n, 1.0 / FPS)
    band = (freq >= 0.3) & (freq <= 5.0)
    total = float(power[1:].sum())
    if total < 1e-12 or not band.any():
        return 0.0, 0.0
    i = int(np.argmax(np.where(band, power, -1.0)))
    return float(freq[i]), float(power[i] / total)


# -- descriptors ------------------------------------------------------------------------------------
def legs_descriptor(joints) -> dict[str, np.ndarray]:
    """Groups of numbers describing the legs and root (module docstring), in leg lengths and seconds."""
    j = check_joints(joints)
    L = leg_length(j)
    theta = headings(j)
    local = body_frame(j, theta) / L
    step = np.einsum("tij,tj->ti", yaw_matrix(-theta[:-1]), j[1:, 0] - j[:-1, 0]) * FPS / L   # root velocity, body frame
    hspeed = np.linalg.norm(step[:, [0, 2]], axis=-1)
    legs = local[:, LEG_JOINTS] - local[:, :1] * np.array([0, 1, 0])                       # relative to the pelvis
    feet_speed = np.linalg.norm(np.diff(legs[:, 4:], axis=0), axis=-1).mean(0) * FPS          # ankles, feet
    feet_h = j[:, [7, 8, 10, 11], 1] / L
    low = feet_h.min(1)
    airborne = float((low > np.quantile(low, 0.05) + 0.06).mean())
    stride = dominant_frequency(legs[:, 4, 2] - legs[:, 5, 2], STRIDE_PAD)[0]
    pose = legs[:, 2:].copy()   # knees, ankles, feet: the hips' place is the skeleton's
    pose[..., 0] -= pose[..., 0].mean(1, keepdims=True)    # across the body: about the legs' own middle
    return {
        "root": np.array([step[:, 2].mean(), step[:, 0].mean(), hspeed.mean(), hspeed.std(), step[:, 1].std()]),
        "direction": np.array([step[:, 2].mean(), step[:, 0].mean()]) / (np.hypot(step[:, 2].mean(), step[:, 0].mean()) + 0.3),
        "height": np.array([local[:, 0, 1].mean(), local[:, 0, 1].std()]),
        "pose": pose.mean(0).ravel(),
        "spread": pose.std(0).ravel(),
        "feet": np.concatenate([feet_speed, [airborne, low.mean()]]),
        "stride": np.array([stride]),
    }


def arms_descriptor(joints) -> dict[str, np.ndarray]:
    """Groups of numbers describing the arms relative to the chest (module docstring), in arm lengths."""
    j = check_joints(joints)
    A = arm_length(j)
    local = body_frame(j, headings(j)) / A
    arms = local[:, ARM_JOINTS] - local[:, CHEST:CHEST + 1]
    vel = np.linalg.norm(np.diff(arms[:, 4:], axis=0), axis=-1) * FPS                          # elbows, wrists
    wrists = arms[:, 6:]
    freq = [dominant_frequency(wrists[:, s, 0]) for s in range(2)] + [dominant_frequency(wrists[:, s, 1]) for s in range(2)]
    return {
        "pose": arms.mean(0).ravel(),
        "spread": arms.std(0).ravel(),
        "range": (wrists.max(0) - wrists.min(0)).ravel(),
        "speed": np.concatenate([vel.mean(0), np.quantile(vel, 0.9, axis=0)]),
        "high": wrists[:, :, 1].max(0),
        "freq": np.array(freq).ravel(),
    }


def side_activity(joints, part: str) -> tuple[float, float]:
    """(left, right): path length of the part's joints relative to the pelvis in the body's frame,
    in metres (``hand``: elbow + wrist; ``foot``: ankle + foot)."""
    if part not in SIDE_JOINTS:
        raise ShapeMoveError(f"part judge: part must be one of {', '.join(SIDE_JOINTS)}, got {part!r}")
    j = check_joints(joints)
    local = body_frame(gaussian_smooth(j, 1.0), headings(j))
    rel = local - local[:, :1]
    path = np.linalg.norm(np.diff(rel, axis=0), axis=-1).sum(0)
    left, right = SIDE_JOINTS[part]
    return float(path[left].sum()), float(path[right].sum())


def side_of(joints, part: str) -> str:
    """"left" or "right": the side whose hand (or foot) moves most relative to the pelvis."""
    left, right = side_activity(joints, part)
    return "left" if left > right else "right"


def path_of(joints) -> str:
    """``CIRCLE`` when the body keeps turning one way while it moves, in every quarter; else ``STRAIGHT``."""
    j = check_joints(joints)
    L = leg_length(j)
    theta = headings(j, 5.0)
    T = len(j)
    signs = []
    for q in range(4):
        a, b = T * q // 4, max(T * (q + 1) // 4, T * q // 4 + 2) - 1
        b = min(b, T - 1)
        secs = max(b - a, 1) / FPS
        turn = np.degrees(theta[b] - theta[a]) / secs
        moved = np.linalg.norm(j[b, 0, [0, 2]] - j[a, 0, [0, 2]]) / secs / L
        if abs(turn) < CIRCLE_DEG_PER_S or moved < MOVING_LEGS_PER_S:
            return STRAIGHT
        signs.append(np.sign(turn))
    return CIRCLE if len(set(signs)) == 1 else STRAIGHT


# -- nearest references ------------------------------------------------------------------------------
class PartKNN:
    """Class-balanced k-NN on one descriptor: a class's score is the mean distance to its ``k``
    nearest references; the lowest wins. Groups are z-scored by the references' spread and weighted
    so each counts equally. ``stretches[i]``: reference i is a stretch of its source clip (its
    steady part), not the whole clip."""

    def __init__(self, descriptors: list[dict], labels: list[str], sources: list[str], describe: Callable, k: int = 5,
                 weights: dict[str, float] | None = None, stretches: list[bool] | None = None):
        if not descriptors or len(descriptors) != len(labels) or len(labels) != len(sources):
            raise ShapeMoveError(f"part judge: {len(descriptors)} reference descriptors for {len(labels)} labels; "
                                 "need at least one of each, equal")
        self.groups = list(descriptors[0])
        self.sizes = [len(descriptors[0][g]) for g in self.groups]
        X = np.stack([self._flat(d) for d in descriptors])
        self.mean = X.mean(0)
        self.scale = np.where(X.std(0) > 1e-8, X.std(0), 1.0)
        w = weights or {}
        self.weights = np.concatenate([np.full(n, w.get(g, 1.0) / np.sqrt(n)) for g, n in zip(self.groups, self.sizes)])
        self.X = self._norm(X)
        self.labels, self.sources = np.asarray(labels), np.asarray(sources)
        self.stretches = np.zeros(len(labels), bool) if stretches is None else np.asarray(stretches, bool)  # a part of its source
        self.classes = sorted(set(labels))
        self.describe, self.k = describe, int(k)

    def _flat(self, d: dict) -> np.ndarray:
        return np.concatenate([np.asarray(d[g], np.float64).ravel() for g in self.groups])

    def _norm(self, X: np.ndarray) -> np.ndarray:
        return (X - self.mean) / self.scale * self.weights

    def scores(self, descriptor: dict, exclude_source: str | None = None) -> dict[str, float]:
        """{class: mean distance to its k nearest references} (lower is closer)."""
        return self.scores_of(self._norm(self._flat(descriptor)), exclude_source)

    def scores_of(self, x: np.ndarray, exclude_source: str | None = None) -> dict[str, float]:
        """``scores`` of a descriptor already normalized (a row of ``self.X``)."""
        d = np.linalg.norm(self.X - x[None], axis=1)
        if exclude_source is not None:  # one source id, or several
            ex = [exclude_source] if isinstance(exclude_source, str) else list(exclude_source)
            d = np.where(np.isin(self.sources, ex), np.inf, d)
        out = {}
        for c in self.classes:
            dc = np.sort(d[self.labels == c])
            dc = dc[np.isfinite(dc)][: self.k]
            if len(dc):
                out[c] = float(dc.mean())
        return out

    def classify(self, joints, exclude_source: str | None = None) -> str:
        return best(self.scores(self.describe(joints), exclude_source))


def best(scores: dict[str, float]) -> str:
    """The class of the lowest score (ties: the first name)."""
    return min(sorted(scores), key=scores.get)


# -- reference clips -----------------------------------------------------------------------------------
def legs_label(acts: list[str]) -> str | None:
    """A real clip's gait (legs and root) from its labels.actions, or None when it is neither a
    locomotion of ``LEGS_ACTIONS`` nor a standing gesture."""
    if not acts:
        return None
    if acts[0] in LEGS_ACTIONS:
        return "walk" if acts[0] == CIRCLE else acts[0]
    if acts[0] in ARMS_ACTIONS and not any(a in LEGS_ACTIONS or ACTIONS.get(a) is not None and
                                           ACTIONS[a].group == "locomotion" for a in acts):
        return STAND
    return None


def arms_label(acts: list[str]) -> str | None:
    """A real clip's gesture: its standing gesture of ``ARMS_ACTIONS``, ``NO_GESTURE`` for a
    locomotion clip of ``LEGS_ACTIONS`` without a gesture, else None."""
    g = legs_label(acts)
    if g == STAND:
        return SAME_MOTION.get(acts[0], acts[0])
    if g is not None and not any(a in ARMS_ACTIONS for a in acts):
        return NO_GESTURE
    return None


def path_label(acts: list[str]) -> str | None:
    g = legs_label(acts)
    return None if g is None or g == STAND else (CIRCLE if CIRCLE in acts else STRAIGHT)


def real_clips(data, split: str) -> list[dict]:
    """Metas of the real captured clips of ``split`` of the built dataset ``data`` (their ``split``)."""
    from ..data.built_meta import iter_meta

    data = Path(data)
    if not (data / FEATURES).is_dir():
        raise ShapeMoveError(f"{data}: not a built dataset (no {FEATURES}/ folder); build one with `data build`")
    return [m for m in iter_meta(data) if m.get("split") == split and is_real(m) and isinstance(m.get("id"), str)]


def actions_of(meta: dict) -> list[str]:
    labels = meta.get("labels") if isinstance(meta.get("labels"), dict) else {}
    if labels.get("sequence"):
        return []
    acts = labels.get("actions")
    return [a for a in acts if isinstance(a, str)] if isinstance(acts, list) else []


def load_joints(data, cid: str) -> np.ndarray | None:
    """The clip's joints from its (T, 263) features, or None when it has no usable features."""
    from .action_classifier import load_features

    f = load_features(data, cid)
    if f is None or len(f) < MIN_FRAMES:
        return None
    try:
        return joints_of(f)
    except ShapeMoveError:
        return None


def _cap(metas: list[dict], label: Callable, max_per_class: int | None, seed: int) -> list[tuple[dict, str]]:
    by: dict[str, list[dict]] = {}
    for m in metas:
        lab = label(actions_of(m))
        if lab is not None:
            by.setdefault(lab, []).append(m)
    rng = np.random.default_rng(seed)
    out = []
    for lab in sorted(by):
        ms = by[lab]
        if max_per_class is not None and len(ms) > max_per_class:
            ms = [ms[i] for i in sorted(rng.choice(len(ms), max_per_class, replace=False))]
        out += [(m, lab) for m in ms]
    return out


class PartJudge:
    """Legs, arms and side of motions (module docstring)."""

    def __init__(self, legs: PartKNN, arms: PartKNN, info: dict | None = None):
        self.legs, self.arms, self.info = legs, arms, dict(info or {})

    @classmethod
    def from_data(cls, data, split: str = "train", max_per_class: int | None = 150, k: int = 5, seed: int = 0,
                  progress: bool = True) -> "PartJudge":
        """References: the real clips of ``split`` of the built dataset ``data`` and their mirrors."""
        return cls.from_metas(data, real_clips(data, split), max_per_class, k, seed, progress, split)

    @classmethod
    def from_metas(cls, data, metas: list[dict], max_per_class: int | None = 150, k: int = 5, seed: int = 0,
                   progress: bool = True, split: str = "") -> "PartJudge":
        from tqdm import tqdm

        legs_refs = _cap(metas, legs_label, max_per_class, seed)
        arms_refs = _cap(metas, arms_label, max_per_class, seed)
        joints: dict[str, np.ndarray | None] = {}
        for m, _ in tqdm(legs_refs + arms_refs, desc="part judge references", unit="clip", disable=not progress):
            if m["id"] not in joints:
                joints[m["id"]] = load_joints(data, m["id"])
        knns = []
        for refs, describe, weights in ((legs_refs, legs_descriptor, LEGS_WEIGHTS), (arms_refs, arms_descriptor, None)):
            descs, labels, sources, stretches = [], [], [], []
            for m, lab in refs:
                j = joints[m["id"]]
                if j is None:
                    continue
                span = steady_span(j) if describe is legs_descriptor and lab != STAND else None
                for jj, stretch in [(j, False)] + ([(j[span[0]:span[1]], True)] if span else []):
                    for kk in (jj, mirror_joints(jj)):
                        descs.append(describe(kk))
                        labels.append(lab)
                        sources.append(m["id"])
                        stretches.append(stretch)
            if not descs:
                raise ShapeMoveError(f"{data}: no real {split or 'reference'} clip of a "
                                     f"{'locomotion or standing gesture' if describe is legs_descriptor else 'gesture'} "
                                     "with usable features; the part judge needs them")
            knns.append(PartKNN(descs, labels, sources, describe, k, weights, stretches))
        count = lambda knn: {c: int(((knn.labels == c) & ~knn.stretches).sum() // 2) for c in knn.classes}  # noqa: E731
        info = {"data": str(data), "split": split, "k": k, "max_per_class": max_per_class,
                "legs_references": count(knns[0]), "arms_references": count(knns[1])}
        return cls(knns[0], knns[1], info)

    def judge_joints(self, joints, exclude_source: str | None = None) -> dict:
        j = check_joints(joints)
        hand, foot = side_activity(j, "hand"), side_activity(j, "foot")
        return {"legs": self.legs.classify(j, exclude_source), "path": path_of(j),
                "arms": self.arms.classify(j, exclude_source),
                "hand_side": "left" if hand[0] > hand[1] else "right",
                "foot_side": "left" if foot[0] > foot[1] else "right",
                "hand_activity_m": [round(v, 3) for v in hand], "foot_activity_m": [round(v, 3) for v in foot]}

    def judge(self, features_list: list, exclude: list | None = None) -> list[dict]:
        """One judgement per (T, 263) features array: legs (gait), path, arms, hand_side, foot_side.
        ``exclude[i]``: reference clip ids motion i must not find (the training clips it was
        retrieved from: a copy is judged without itself), or None."""
        ex = exclude if exclude is not None else [None] * len(features_list)
        return [self.judge_joints(joints_of(f), e or None) for f, e in zip(features_list, ex)]


def legs_right(expected: str, judged: dict) -> bool:
    """Expected ``CIRCLE``: the path circles and the legs move; else the gait is the expected one."""
    if expected == CIRCLE:
        return judged["path"] == CIRCLE and judged["legs"] != STAND
    return judged["legs"] == expected


def arms_right(expected: str, judged: dict) -> bool:
    return judged["arms"] == SAME_MOTION.get(expected, expected)
