"""Where a motion's root travel goes in the rig (Blender-free, torch-free scene maths).

Modes (the panel's "Root motion", the export carries it):
- ``PELVIS``: as generated, the pelvis bone carries the travel (the default);
- ``OBJECT``: the pelvis stays over the start point (horizontally) and the armature object's
  location carries the travel;
- ``ROOT_BONE``: the same travel on a ``root`` bone at the origin, the pelvis's parent (engines'
  root motion);
- ``NONE``: in place, the travel removed (facing and height kept).
``rig_channels`` also closes a loop: a looping motion (``loop_advance``) gets one frame more, frame
0 moved by the advance, so the keys' last value minus their first is the per-cycle offset that a
Cycles modifier in "Repeat with Offset" mode adds each cycle to the translations (the rotations
repeat as they are: ``shapemove_addon/animation_rig.py``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ShapeMoveError

MODES = ("PELVIS", "OBJECT", "ROOT_BONE", "NONE")
ROOT_BONE = "root"


def root_travel(joints) -> np.ndarray:
    """(T,3) horizontal offset (Y up, y = 0) of the root joint from its first frame."""
    j = np.asarray(joints, np.float64)
    d = np.zeros((len(j), 3))
    d[:, [0, 2]] = j[:, 0, [0, 2]] - j[0, 0, [0, 2]]
    return d


@dataclass
class RigChannels:
    poses: np.ndarray           # (N,24,3) axis-angle, Y up
    transl: np.ndarray          # (N,3) pelvis offset, Y up (without the travel unless PELVIS)
    travel: np.ndarray | None   # (N,3) Y up: for OBJECT / ROOT_BONE, else None
    cycle: int | None           # frames of one cycle of a loop (N = cycle + 1), else None


def rig_channels(motion, mode: str = "PELVIS") -> RigChannels:
    mode = str(mode).upper()
    if mode not in MODES:
        raise ShapeMoveError(f"root motion must be one of {', '.join(MODES)}, got {mode!r}")
    poses = np.asarray(motion.poses, np.float64)
    transl = np.asarray(motion.transl, np.float64)
    travel = root_travel(motion.joints)
    cycle = None
    if motion.loop_advance is not None:
        adv = np.asarray(motion.loop_advance, np.float64)
        cycle = len(poses)
        poses = np.concatenate([poses, poses[:1]])
        transl = np.concatenate([transl, transl[:1] + adv[None]])
        travel = np.concatenate([travel, [[adv[0], 0.0, adv[2]]]])
    if mode != "PELVIS":
        transl = transl - travel
    return RigChannels(poses.astype(np.float32), transl.astype(np.float32),
                       travel if mode in ("OBJECT", "ROOT_BONE") else None, cycle)
