"""What every mocap reader returns: ``Mocap`` (a skeleton and its motion in metres, Y up) and
``finish_mocap``, which turns arrays in the file's units and axes into one. A leaf of ``core.io``:
the readers (bvh, asf_amc, amass, deepmimic) import it, and ``mocap.load_mocap`` imports the readers.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ShapeMoveError
from ..geometry.fk import joints_from_offsets
from .units_axes import detect_unit, detect_up_axis, smpl22_or_none, to_y_up


@dataclass
class Mocap:
    """A skeleton and its motion.

    names (J,) joint names (End Sites are joints named ``<parent>_End``); parents (J,) int, -1 for
    the root, parents[j] < j; offsets (J,3) metres, Y up: each joint's rest position relative to
    its parent (the root's is its rest position); positions (T,J,3) metres, Y up, world;
    rotations (T,J,3,3) local joint rotations in the same frame, or None: FK of the offsets with
    these rotations, the root placed at positions[:, 0], gives the positions (BVH joints with
    position channels, like Bandai's, translate by their channels instead of their offsets);
    fps frames per second; ``unit`` (m/cm/mm/inch/asf ...), ``scale`` (metres per file unit) and
    ``up_axis`` (Y/Z/...) as found in the file; ``subject`` the performer (CMU subject number,
    HDM05 actor, 'bandai'); ``meta`` reader extras (BVH channels, ASF path, AMASS betas).
    """

    names: list
    parents: np.ndarray
    offsets: np.ndarray
    positions: np.ndarray
    fps: float
    source: str = ""
    rotations: np.ndarray | None = None
    unit: str = "m"
    scale: float = 1.0
    up_axis: str = "Y"
    subject: str = ""
    meta: dict = field(default_factory=dict)

    @property
    def num_frames(self) -> int:
        return int(self.positions.shape[0])

    @property
    def num_joints(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        return self.names.index(name)

    def bone_lengths(self) -> np.ndarray:
        """(J,) rest bone lengths in metres (norm of the offsets; 0 for the root)."""
        out = np.linalg.norm(self.offsets, axis=-1)
        out[np.asarray(self.parents) < 0] = 0.0
        return out


def finish_mocap(names, parents, offsets, positions, fps, source, *, rotations=None, unit=None,
                 scale=None, up_axis=None, subject="", meta=None) -> Mocap:
    """Build a Mocap from arrays in FILE units and axes: detect the unit and up axis where not
    given, convert to metres and Y up, check that everything is finite."""
    positions = np.asarray(positions, dtype=np.float64)
    if positions.ndim != 3 or positions.shape[0] < 1 or positions.shape[2] != 3:
        raise ShapeMoveError(f"{source}: no frames of joint positions")
    if not np.all(np.isfinite(positions)):
        raise ShapeMoveError(f"{source}: joint positions are not finite (NaN/inf or numbers too large in the file)")
    offsets = np.asarray(offsets, dtype=np.float64)
    rest = joints_from_offsets(offsets, parents)  # rest skeleton: an unknown rig is matched on it
    j22 = smpl22_or_none(names, positions, parents, rest) if scale is None or up_axis is None else None
    if scale is None:
        unit, scale = detect_unit(names, positions, smpl22=j22)
    if up_axis is None:
        up_axis = detect_up_axis(names, positions, rest=rest, smpl22=j22, parents=parents)
    R = to_y_up(up_axis)
    A = R * float(scale)
    positions = positions @ A.T
    offsets = offsets @ A.T
    if rotations is not None and up_axis != "Y":
        rotations = R @ rotations @ R.T
    if not (np.all(np.isfinite(positions)) and np.all(np.isfinite(offsets))):
        raise ShapeMoveError(f"{source}: joint positions overflow after unit conversion")
    if not (np.isfinite(fps) and 0.5 <= fps <= 10000):
        raise ShapeMoveError(f"{source}: implausible frame rate {fps}")
    return Mocap(list(names), np.asarray(parents, dtype=np.int64), offsets, positions, float(fps), str(source),
                 rotations, unit or "m", float(scale), up_axis, subject, dict(meta or {}))
