"""A motion-capture clip in ShapeMove's frame (metres, Y up), whatever file it came from, and the
one call the dataset builder and the IK benchmark use: ``load_smpl22(path) -> Motion22``.

``load_mocap`` dispatches on the extension: ``.bvh``, ``.amc`` (its ``.asf`` is found beside it),
``.npz`` (AMASS, needs a body model), ``.txt``/``.json`` (DeepMimic JSON motions).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..body.skeleton import PARENTS
from ..constants import FPS
from ..errors import ShapeMoveError
from ..geometry.fk import joints_from_offsets
from .asf_amc import load_amc
from .bvh import load_bvh
from .deepmimic import load_deepmimic
from .mocap_clip import Mocap
from .resample import resample_positions
from .rig_map import detect_rig, mapping_matrix, pose_candidates
from .tpose import tpose_lead_in


def load_mocap(path, body_model=None, **kwargs) -> Mocap:
    """Read a ``.bvh``, ``.amc`` (with the ``.asf`` beside it), AMASS ``.npz`` or DeepMimic ``.txt``/``.json`` file."""
    path = Path(path)
    if not path.is_file():
        raise ShapeMoveError(f"motion file not found: {path}")
    ext = path.suffix.lower()
    if ext == ".bvh":
        return load_bvh(path, **kwargs)
    if ext == ".amc":
        return load_amc(path, **kwargs)
    if ext == ".npz":
        from .amass import load_amass

        return load_amass(path, body_model=body_model, **kwargs)
    if ext in (".txt", ".json"):
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
        par = PARENTS[:22]
        out = np.zeros(22)
        out[1:] = np.median(np.linalg.norm(self.joints[:, 1:] - self.joints[:, par[1:]], axis=-1), axis=0)
        return out


def mocap_to_smpl22(mocap: Mocap, fps: float = FPS, drop_tpose: bool = True) -> Motion22:
    """Map a Mocap to SMPL22 positions, cut a T-pose lead-in, resample to ``fps``."""
    rig = detect_rig(mocap.names, mocap.parents,
                     pose_candidates(joints_from_offsets(mocap.offsets, mocap.parents), mocap.positions))
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


def reader_options(path, source_fps: float | None = None, angle_unit: str | None = None) -> dict:
    """The user's overrides of what a mocap file declares, as keyword arguments of its reader:
    ``source_fps`` (BVH Frame Time, AMC frame rate) and ``angle_unit`` ('deg'/'rad', ASF/AMC only).
    An override the file's format does not have is a ShapeMoveError, not silently ignored."""
    ext = Path(path).suffix.lower()
    out = {}
    if source_fps is not None:
        if ext not in (".bvh", ".amc"):
            raise ShapeMoveError(f"{path}: --source-fps applies to BVH and AMC files only")
        out["fps"] = float(source_fps)
    if angle_unit is not None:
        if ext != ".amc":
            raise ShapeMoveError(f"{path}: --angle-unit applies to ASF/AMC files only")
        out["angle_unit"] = angle_unit
    return out


def load_smpl22(path, fps: float = FPS, body_model=None, drop_tpose: bool = True, source_fps: float | None = None,
                angle_unit: str | None = None) -> Motion22:
    """Any supported mocap file -> Motion22 at ``fps`` (default 20), T-pose lead-in removed.
    ``source_fps`` / ``angle_unit``: see ``reader_options``."""
    return mocap_to_smpl22(load_mocap(path, body_model=body_model, **reader_options(path, source_fps, angle_unit)),
                           fps=fps, drop_tpose=drop_tpose)
