"""Physical signatures of actions: checks on a motion's joints that say whether it shows an action,
independent of any learnt model.

The sequence evaluation (``sequence_eval.py``) judges most segments by the 5-NN vote on pooled raw
features, which names real captured jumps 0 % of the time, real get-ups 0 % and real spins 0 %
(``reachable``): among 3,800 references, a jump's few seconds sit nearer the walks. An action with
a plain physical signature is checked for it instead, on the (T, 22, 3) joints (y up, the floor at
0, ``FPS``), every length in units of the body's leg length ``L`` (hip to knee to ankle):

- **jump** (and its forms: a jump forward, a spin jump, a hop): a flight, at least ``FLIGHT_FRAMES``
  frames with every foot joint ``FLIGHT`` L or more off the floor, while the pelvis is ``JUMP_RISE`` L
  or more above its median height (a run's flights lift it 0.07-0.13 L, jumps 0.24-0.59 L, jumping
  jacks 0.17-0.18 L);
- **squat**: the pelvis comes down to ``SQUAT_LOW`` of where it starts, the head above ``HEAD_UP`` of
  its highest (not lying), the feet within ``STAY`` m of where they start;
- **lie down**: the head ends under ``LYING`` of its highest, having been ``UPRIGHT_HEAD`` L high or more (sitting up: 0.8 L; lying: 0.15 L);
- **get up**: the pelvis ends at least ``RISE`` L higher than it starts, from under ``LOW_START`` L;
- **spin**: the body (its hips and shoulders) turns ``SPIN`` radians or more one way within ``SPIN_SECONDS`` (a figure eight
  walked turns 1 rad/s);
- **kick**: a foot's ankle ``KICK_HIGH`` L or more above the floor, ``KICK_AHEAD`` L or more in front
  of the pelvis (a run's heel kicks up behind it);
- **wave** (and a wave goodbye): a wrist above its shoulder swings side to side across the body,
  turning back ``WAVE_TURNS`` times or more, each swing ``WAVE_SWING`` m or more (a raised hand held
  up does not: the part judge's arms, built on whole takes, read 3 s of a captured two-handed wave,
  hands up and swinging, as a raised hand);
- **jumping jacks**: two hops or more in place (every foot joint ``FLIGHT`` L or more off the floor
  for ``FLIGHT_FRAMES`` frames, the pelvis slower than ``IN_PLACE`` m/s: a run's flights go 2-3 m/s),
  the wrists above the head and the ankles ``JACKS_SPREAD`` L or more apart at some frames.

Each is measured on the built data's real training clips (``tools/signature_check.py``): how often
the clips of the action pass and how often those of every other action do (docs/evaluation.md).

    signatures(joints)      # {"jump": False, "squat": True, ...}
"""
from __future__ import annotations

import numpy as np

from ..body.skeleton import JOINT_NAMES
from ..constants import FPS
from ..errors import ShapeMoveError
from ..motion.contacts import runs
from ..motion.skeleton_ops import facing_directions, heading_angles, leg_length

_J = {n: JOINT_NAMES.index(n) for n in ("pelvis", "head", "left_hip", "right_hip", "left_knee", "right_knee",
                                         "left_ankle", "right_ankle", "left_foot", "right_foot",
                                         "left_wrist", "right_wrist")}
FEET = [_J["left_ankle"], _J["right_ankle"], _J["left_foot"], _J["right_foot"]]

FLIGHT, FLIGHT_FRAMES, JUMP_RISE = 0.08, 2, 0.15
HEAD_UP = 0.4   # a head under this share of its highest lies (a deep squat's: 0.52-0.71)
SQUAT_LOW, STAY = 0.75, 0.5
LYING = 0.35
RISE, LOW_START = 0.35, 0.7
SPIN, SPIN_SECONDS = 1.5 * np.pi, 2.0
UPRIGHT_HEAD = 0.6   # L: a head this high at some frame was up (sitting or higher) before lying
KICK_HIGH, KICK_AHEAD = 0.6, 0.3
JACKS_SPREAD, IN_PLACE = 0.5, 1.0
WAVE_TURNS, WAVE_SWING, WAVE_FRAMES = 3, 0.06, 10   # a wave's turns and swing (m); frames the wrist is up
ENDS = 5   # frames averaged at a segment's start and end

SIGNED = ("jump", "squat", "lie down", "get up", "spin", "kick", "jumping jacks", "wave")
WAVES = ("wave", "wave goodbye")                     # the forms of a wave its signature reads
JUMPS = ("jump", "jump forward", "spin jump", "hop")   # the forms of a jump its signature reads


def flights(joints, leg: float) -> list[tuple[int, int]]:
    """The flights of a jump: runs of at least ``FLIGHT_FRAMES`` frames with every foot joint
    ``FLIGHT`` x ``leg`` off the floor and the pelvis ``JUMP_RISE`` x ``leg`` above its median."""
    j = np.asarray(joints, dtype=np.float64)
    up = (j[:, FEET, 1].min(axis=1) >= FLIGHT * leg) & (j[:, 0, 1] >= np.median(j[:, 0, 1]) + JUMP_RISE * leg)
    return [(a, b) for a, b in runs(up) if b - a >= FLIGHT_FRAMES]


def turns(x, swing: float) -> int:
    """How often a (T,) signal turns back after moving ``swing`` or more one way (hysteresis)."""
    n, way = 0, 0
    hi = lo = float(x[0]) if len(x) else 0.0
    for v in np.asarray(x, dtype=np.float64)[1:]:
        hi, lo = max(hi, v), min(lo, v)
        if way != -1 and hi - v >= swing:
            n, way, hi, lo = n + (way == 1), -1, v, v
        elif way != 1 and v - lo >= swing:
            n, way, hi, lo = n + (way == -1), 1, v, v
    return n


def waves(joints) -> bool:
    """Whether a wrist, above its shoulder for ``WAVE_FRAMES`` frames or more, swings side to side
    across the body (along the hips' left-right axis) turning back ``WAVE_TURNS`` times or more."""
    j = np.asarray(joints, dtype=np.float64)
    across = j[:, _J["right_hip"]] - j[:, _J["left_hip"]]
    across /= np.maximum(np.linalg.norm(across, axis=1, keepdims=True), 1e-9)
    for side in ("left", "right"):
        w, s = _J[f"{side}_wrist"], JOINT_NAMES.index(f"{side}_shoulder")
        up = j[:, w, 1] > j[:, s, 1]
        if up.sum() >= WAVE_FRAMES and turns(np.einsum("tk,tk->t", (j[:, w] - j[:, s])[up], across[up]),
                                             WAVE_SWING) >= WAVE_TURNS:
            return True
    return False


def facing_yaw(joints) -> np.ndarray:
    """(T,) the way the body faces (radians about y, 0 facing +z, unwrapped: ``skeleton_ops``'s
    facing of the hips and shoulders); zeros where it cannot be told (hips and shoulders vertical)."""
    try:
        return np.unwrap(heading_angles(facing_directions(np.asarray(joints, dtype=np.float64))))
    except ShapeMoveError:
        return np.zeros(len(joints))


def signatures(joints, fps: float = FPS) -> dict[str, bool]:
    """{action: whether (T, 22, 3) ``joints`` show its signature} for every action of ``SIGNED``."""
    j = np.asarray(joints, dtype=np.float64)
    leg = max(leg_length(j), 1e-6)
    pelvis, head = j[:, 0, 1], j[:, _J["head"], 1]
    n = min(ENDS, len(j))
    feet_moved = float(np.linalg.norm(j[-n:, FEET][:, :, [0, 2]].mean(axis=(0, 1))
                                      - j[:n, FEET][:, :, [0, 2]].mean(axis=(0, 1))))
    lies = head[-n:].mean() < LYING * head.max()
    out = {"jump": bool(flights(j, leg))}
    out["squat"] = bool(pelvis.min() <= SQUAT_LOW * pelvis[:n].mean() and head.min() >= HEAD_UP * head.max()
                        and feet_moved <= STAY)
    out["lie down"] = bool(lies and head.max() >= UPRIGHT_HEAD * leg)
    out["get up"] = bool(pelvis[:n].mean() <= LOW_START * leg and pelvis[-n:].mean() - pelvis[:n].mean() >= RISE * leg)
    yaw = facing_yaw(j)
    w = min(max(2, int(round(SPIN_SECONDS * fps))), len(yaw) - 1)   # the turn over SPIN_SECONDS (or all of it)
    out["spin"] = bool(w > 0 and np.abs(yaw[w:] - yaw[:-w]).max() >= SPIN)
    forward = np.stack([np.sin(yaw), np.cos(yaw)], axis=1)
    kick = False
    for a in (_J["left_ankle"], _J["right_ankle"]):
        ahead = np.einsum("tk,tk->t", j[:, a][:, [0, 2]] - j[:, 0][:, [0, 2]], forward)
        kick |= bool(((j[:, a, 1] >= KICK_HIGH * leg) & (ahead >= KICK_AHEAD * leg)).any())
    out["kick"] = kick
    hands_up = (np.minimum(j[:, _J["left_wrist"], 1], j[:, _J["right_wrist"], 1]) > head).any()
    spread = (np.linalg.norm(j[:, _J["left_ankle"]][:, [0, 2]] - j[:, _J["right_ankle"]][:, [0, 2]], axis=1)
              >= JACKS_SPREAD * leg).any()
    off = j[:, FEET, 1].min(axis=1) >= FLIGHT * leg
    speed = np.concatenate([[0.0], np.linalg.norm(np.diff(j[:, 0][:, [0, 2]], axis=0), axis=1) * fps])
    hops = [(a, b) for a, b in runs(off) if b - a >= FLIGHT_FRAMES and speed[a:b].mean() < IN_PLACE]
    out["jumping jacks"] = bool(len(hops) >= 2 and hands_up and spread)
    out["wave"] = waves(j)
    return out


def signed(action: str | None) -> str | None:
    """The signature that reads ``action`` (a form of a jump reads as a jump), or None."""
    if action in JUMPS:
        return "jump"
    if action in WAVES:
        return "wave"
    return action if action in SIGNED else None
