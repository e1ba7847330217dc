"""Per-skeleton calibration of where a mocap rig's torso and girdle joints sit on the body.

A mocap rig's pelvis, hip, spine, neck, collar, head and shoulder joints are not at the same
anatomical spots as the body model's joint centres (as MoSh's markers are not at joint centres):
Bandai's shoulder joints sit ~4 cm from OpenBody's, CMU's upper neck ~5 cm, HDM05's collars ~4 cm.
Asking the body's joint centres to reach those points bends its collars and spine into poses
the subject never held. So, once per clip (one source skeleton), each of those joints k gets a
constant offset d_k carried by the body segment it sits on (the frame of its parent bone, i.e.
the parent joint's world rotation G_p(k); the pelvis: its own), and the IK solves for

    FK_k(pose) + G_p(k)(pose) d_k  =  mocap joint k

(``marker_points``). The offsets are found in closed form alternated with the IK
(``calibrate_offsets``): with the pose held, the least-squares d_k is the mean over the frames of
G_p(k)^T (target_k - FK_k), shrunk by ``OFFSET_SHRINK`` (a ridge) and bounded to ``MAX_OFFSET``;
the IK then solves for the corrected targets target_k - G_p(k) d_k (``corrected_targets``).
An offset on a segment with a single child (neck -> head, collar -> shoulder) is determined only up
to a constant turn of that segment, which the pose absorbs; what the calibration determines is the
body's calibrated points (and e.g. a shoulder's distance from its collar joint).

The limbs (knees, elbows, ankles, feet, wrists) are NOT calibrated: their joint centres are
well defined in every rig and the foot contacts are planted on them. Two errors describe a
result: the marker error (mocap joint vs the body's calibrated point: what the IK fits) and the
raw joint-centre error (mocap joint vs the body's joint centre; on calibrated joints it includes
the offset). The output pose is a normal body pose (local rotations + transl).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..errors import ShapeMoveError
from ..geometry.torch_ops import forward_kinematics
from .ik import IKResult, solve_ik
from .skeleton import JOINT_INDEX, NUM_BODY_JOINTS, PARENTS

# pelvis, hips, spine1-3, neck, collars, head, shoulders: the joints whose definitions differ by rig
CALIBRATED_JOINTS = tuple(JOINT_INDEX[n] for n in (
    "pelvis", "left_hip", "right_hip", "spine1", "spine2", "spine3", "neck", "left_collar", "right_collar",
    "head", "left_shoulder", "right_shoulder"))
MAX_OFFSET = 0.06      # metres: an offset's length is clipped to this
OFFSET_SHRINK = 0.02   # ridge: the least-squares offset divided by (1 + OFFSET_SHRINK)
CALIB_ROUNDS = 4       # IK <-> offsets alternations
CALIB_FRAMES = 48      # evenly spread frames the calibration looks at (96: the same errors to 0.01 cm on bench ik's clips)
_CARRIER = np.array([0] + list(PARENTS[1:NUM_BODY_JOINTS]))  # segment carrying each joint's offset


@dataclass
class CalibratedIK:
    ik: IKResult               # the pose (on all frames) solved for the corrected targets
    offsets: np.ndarray        # (22,3) metres, in each joint's carrying frame (0 for uncalibrated joints)
    marker_error: np.ndarray   # (T,22) metres, |FK + G d - target|
    raw_error: np.ndarray      # (T,22) metres, |FK - target| (joint centres)

    @property
    def marker_error_cm(self) -> float:
        return float(self.marker_error.mean()) * 100.0

    @property
    def raw_error_cm(self) -> float:
        return float(self.raw_error.mean()) * 100.0

    @property
    def offset_cm(self) -> np.ndarray:
        """(22,) length of each joint's offset, centimetres."""
        return np.linalg.norm(self.offsets, axis=-1) * 100.0


def _pose(rotations, transl, rest) -> tuple[np.ndarray, np.ndarray]:
    """FK positions (T,22,3) and the carrying frames (T,22,3,3) of an IK pose."""
    rot = torch.as_tensor(np.asarray(rotations), dtype=torch.float64)
    r = torch.as_tensor(np.asarray(rest, dtype=np.float64)).reshape(-1, 3)
    pos, world = forward_kinematics(rot, r.expand(rot.shape[0], -1, -1), PARENTS)
    pos = pos[:, :NUM_BODY_JOINTS].numpy() + np.asarray(transl, dtype=np.float64)[:, None]
    return pos, world[:, _CARRIER].numpy()


def marker_points(rotations, transl, rest_joints, offsets) -> np.ndarray:
    """(T,22,3) the body's calibrated points: joint centres + offsets in their carrying frames."""
    pos, frames = _pose(rotations, transl, rest_joints)
    return pos + np.einsum("tkab,kb->tka", frames, np.asarray(offsets, dtype=np.float64))


def corrected_targets(joints, frames, offsets) -> np.ndarray:
    """IK targets for the joint centres: mocap joints (T,22,3) minus the offsets (22,3) carried by
    ``frames`` (T,22,3,3), the carrying frames of a pose close to the answer."""
    return np.asarray(joints, dtype=np.float64)[:, :NUM_BODY_JOINTS] - np.einsum("tkab,kb->tka", frames, offsets)


def _check(joints, max_offset, shrink, rounds):
    x = np.asarray(joints, dtype=np.float64)
    if x.ndim != 3 or x.shape[0] < 1 or x.shape[1] not in (NUM_BODY_JOINTS, 24) or x.shape[2] != 3:
        raise ShapeMoveError(f"calibration joints must be (frames, 22, 3) metres, got shape {x.shape}")
    if not np.isfinite(x).all():
        raise ShapeMoveError("calibration joints contain NaN or infinite values")
    if not (0 <= max_offset <= 0.2) or shrink < 0 or rounds < 1:
        raise ShapeMoveError("max_offset must be 0..0.2 m, shrink >= 0 and rounds >= 1")
    return x[:, :NUM_BODY_JOINTS]


def _mask(calibrated) -> np.ndarray:
    m = np.zeros((NUM_BODY_JOINTS, 1))
    idx = [JOINT_INDEX.get(c, -1) if isinstance(c, str) else int(c) for c in calibrated]
    if any(not 0 <= k < NUM_BODY_JOINTS for k in idx):
        raise ShapeMoveError(f"calibrated joints must be among the {NUM_BODY_JOINTS} body joints")
    m[idx] = 1.0
    return m


def calibrate_offsets(joints, rest_joints, refine_iters: int = 10, rounds: int = CALIB_ROUNDS,
                      frames: int = CALIB_FRAMES, max_offset: float = MAX_OFFSET, shrink: float = OFFSET_SHRINK,
                      calibrated=CALIBRATED_JOINTS) -> np.ndarray:
    """(22,3) constant offsets (metres, carrying frames) of the ``calibrated`` joints of a clip's
    skeleton on the body with ``rest_joints`` (24,3): ``rounds`` alternations of the IK
    (``refine_iters`` steps) on ``frames`` evenly spread frames and the closed-form offsets
    (the mean of G^T (target - FK) / (1 + shrink), each clipped to ``max_offset`` metres)."""
    x = _check(joints, max_offset, shrink, rounds)
    mask = _mask(calibrated)
    x = x[np.unique(np.linspace(0, len(x) - 1, min(frames, len(x))).round().astype(int))]
    d = np.zeros((NUM_BODY_JOINTS, 3))
    tgt = x
    for _ in range(rounds):
        res = solve_ik(tgt, rest_joints, refine_iters=refine_iters)
        pos, fr = _pose(res.rotations, res.transl, rest_joints)
        d = np.einsum("tkba,tkb->ka", fr, x - pos) / len(x) / (1.0 + shrink) * mask
        n = np.linalg.norm(d, axis=-1, keepdims=True)
        d = d * np.minimum(1.0, max_offset / np.maximum(n, 1e-12))
        tgt = corrected_targets(x, fr, d)
    return d


def solve_ik_calibrated(joints, rest_joints, refine_iters: int = 10, offsets=None, **calib) -> CalibratedIK:
    """IK of a mocap clip (T,22,3) onto the body with ``rest_joints`` (24,3) with the clip's
    torso/girdle joints calibrated (``calibrate_offsets``; or the given ``offsets`` (22,3)):
    the analytic IK's carrying frames correct the targets, the IK (``refine_iters`` steps) solves
    them on all frames. Returns the pose, the offsets and both errors (see the module docstring)."""
    x = _check(joints, calib.get("max_offset", MAX_OFFSET), calib.get("shrink", OFFSET_SHRINK),
               calib.get("rounds", CALIB_ROUNDS))
    if offsets is None:
        d = calibrate_offsets(x, rest_joints, refine_iters=refine_iters, **calib)
    else:
        d = np.asarray(offsets, dtype=np.float64)
        if d.shape != (NUM_BODY_JOINTS, 3) or not np.isfinite(d).all():
            raise ShapeMoveError(f"offsets must be ({NUM_BODY_JOINTS}, 3) finite metres, got shape {d.shape}")
    if np.abs(d).max() == 0:
        res = solve_ik(x, rest_joints, refine_iters=refine_iters)
    else:
        first = solve_ik(x, rest_joints, refine_iters=0)  # carrying frames close to the answer
        _, fr = _pose(first.rotations, first.transl, rest_joints)
        res = solve_ik(corrected_targets(x, fr, d), rest_joints, refine_iters=refine_iters)
    pos, fr = _pose(res.rotations, res.transl, rest_joints)
    marker = np.linalg.norm(pos + np.einsum("tkab,kb->tka", fr, d) - x, axis=-1)
    raw = np.linalg.norm(pos - x, axis=-1)
    return CalibratedIK(ik=res, offsets=d, marker_error=marker, raw_error=raw)
