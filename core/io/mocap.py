"""A motion-capture clip in ShapeMove's frame (metres, Y up), whatever file it came from, and the
one call the dataset builder and the IK benchmark use: ``load_smpl22(path) -> Motion22``.

``load_mocap`` dispatches on the extension: ``.bvh``, ``.amc`` (its ``.asf`` is found beside it),
``.npz`` (AMASS, needs a body model), ``.txt``/``.json`` (DeepMimic JSON motions).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

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
    j22 = smpl22_or_none(names, positions) if scale is None or up_axis is None else None
    if scale is None:
        unit, scale = detect_unit(names, positions, smpl22=j22)
    if up_axis is None:
        rest = joints_from_offsets(offsets, parents)
        up_axis = detect_up_axis(names, positions, rest=rest, smpl22=j22)
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


def load_mocap(path, body_model=None, **kwargs) -> Mocap:
    """Read a ``.bvh``, ``.amc`` (with the ``.asf`` beside it), AMASS ``.npz`` or DeepMimic ``.txt``/``.json`` file."""
    path = Path(path)
    if not path.is_file():
        raise ShapeMoveError(f"motion file not found: {path}")
    ext = path.suffix.lower()
    if ext == ".bvh":
        from .bvh import load_bvh
        return load_bvh(path, **kwargs)
    if ext == ".amc":
        from .asf_amc import load_amc
        return load_amc(path, **kwargs)
    if ext == ".npz":
        from .amass import load_amass
        return load_amass(path, body_model=body_model, **kwargs)
    if ext in (".txt", ".json"):
        from .deepmimic import load_deepmimic
        return load_deepmimic(path, **kwargs)
    raise ShapeMoveError(f"{path}: unsupported motion file type {ext!r} (use .bvh, .amc, AMASS .npz or DeepMimic .txt)")


@dataclass
class Motion22:
    """A clip on the 22 SMPL body joints (HumanML3D order).

    joints (T,22,3) metres, Y up, at ``fps``; offsets (22,3) metres: each SMPL joint's rest offset
    from its SMPL parent in the source's rest skeleton (through the same joint mapping; pelvis row
    zero) -- ``bone_lengths()`` gives the lengths measured over the motion itself, which do not
    depend on the source's rest-pose convention. ``dropped_frames``: source frames cut as T-pose
    lead-in. ``rig``: the source skeleton family.
    """

    joints: np.ndarray
    fps: float
    source: str
    subject: str
    offsets: np.ndarray
    rig: str = ""
    dropped_frames: int = 0

    @property
    def num_frames(self) -> int:
        return int(self.joints.shape[0])

    def bone_lengths(self) -> np.ndarray:
        """(22,) median over frames of |joint - SMPL parent| in metres (0 for the pelvis)."""
        from ..body.skeleton import PARENTS
        par = PARENTS[:22]
        out = np.zeros(22)
        out[1:] = np.median(np.linalg.norm(self.joints[:, 1:] - self.joints[:, par[1:]], axis=-1), axis=0)
        return out


def mocap_to_smpl22(mocap: Mocap, fps: float = 20.0, drop_tpose: bool = True) -> Motion22:
    """Map a Mocap to SMPL22 positions, cut a T-pose lead-in, resample to ``fps``."""
    from ..body.skeleton import PARENTS
    from .resample import resample_positions
    from .rig_map import detect_rig, mapping_matrix
    from .tpose import tpose_lead_in

    rig = detect_rig(mocap.names, mocap.parents, joints_from_offsets(mocap.offsets, mocap.parents))
    W = mapping_matrix(rig, mocap.names, mocap.positions)
    joints = np.matmul(W, mocap.positions)
    cut = tpose_lead_in(joints, mocap.fps) if drop_tpose else 0
    if cut > 0 and cut >= len(joints) - 1:
        raise ShapeMoveError(f"{mocap.source}: the clip holds nothing but a T-pose")
    joints = resample_positions(joints[cut:], mocap.fps, fps)
    # rest skeleton: FK of the offsets with identity rotations, mapped like the motion
    rest = joints_from_offsets(mocap.offsets, mocap.parents)
    rest22 = W @ rest
    par = PARENTS[:22]
    offsets = np.zeros((22, 3))
    offsets[1:] = rest22[1:] - rest22[par[1:]]
    return Motion22(joints, float(fps), mocap.source, mocap.subject, offsets, rig.name, int(cut))


def load_smpl22(path, fps: float = 20.0, body_model=None, drop_tpose: bool = True) -> Motion22:
    """Any supported mocap file -> Motion22 at ``fps`` (default 20), T-pose lead-in removed."""
    return mocap_to_smpl22(load_mocap(path, body_model=body_model), fps=fps, drop_tpose=drop_tpose)
