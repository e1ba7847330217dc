"""In place: the same motion without its horizontal root travel (engines that move the character
themselves, crowds, previews).

The root (pelvis) keeps its height and every rotation (so the facing and the turns stay); its
horizontal position is held at the first frame's. The whole body moves with it, so the feet now
slide under the body exactly as much as it travelled (a treadmill): they still step and alternate
as in the original. A loop's ``loop_advance`` loses its horizontal part. The motion says so
(``Motion.held_in_place``, kept in its file), so re-decoding it for another body
(``Generator.redecode``) and regenerating a timeline's strip hold it in place again.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..scene.motion_file import Motion
from ..scene.root_motion import root_travel as travel_of_joints


def root_travel(motion: Motion) -> np.ndarray:
    """(T,3) horizontal offset of the root from its first frame (y = 0)."""
    return travel_of_joints(motion.joints)


def root_drift(motion: Motion) -> float:
    """Largest horizontal distance (m) of the root from where it starts."""
    return float(np.linalg.norm(root_travel(motion), axis=1).max())


def in_place(motion: Motion) -> Motion:
    """``motion`` with its root held over its first frame's position (height, rotations kept)."""
    d = root_travel(motion)
    out = dataclasses.replace(motion, transl=(motion.transl - d).astype(np.float32),
                              joints=(motion.joints - d[:, None]).astype(np.float32))
    if motion.network_joints is not None:
        out.network_joints = (motion.network_joints - d[:, None]).astype(np.float32)
    if motion.loop_advance is not None:
        out.loop_advance = np.array([0.0, motion.loop_advance[1], 0.0], np.float32)
    out.warnings = list(motion.warnings)
    out.held_in_place = True
    return out
