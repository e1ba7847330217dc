"""AMASS-style ``.npz`` reader: SMPL(-H/-X) pose parameters -> joint positions through a body model.

Keys: ``poses`` (T, >=66) axis-angle (root orient + 21 body joints first), ``trans`` (T,3) metres,
``betas`` (>=1), ``mocap_framerate`` (or ``mocap_frame_rate``), optional ``gender``. AMASS is
Z up; the result is Y up (``(x, y, z) -> (x, z, -y)``, a rotation: left stays left).

The body joints come from ``body_model`` (a ``core.body.model.BodyModel``; default OpenBody).
AMASS betas belong to the SMPL family's shape space, so they are applied only when the model is an
SMPL-family model (``is_smpl_family``); other models use their mean shape unless
``betas=True`` forces them.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from ..body.openbody import OpenBody
from ..geometry.fk import bone_offsets, forward_kinematics
from ..geometry.rotations import axis_angle_to_matrix
from ..body.skeleton import JOINT_NAMES, NUM_BODY_JOINTS, PARENTS
from ..errors import ShapeMoveError
from .limits import check_joint_frames
from .mocap_clip import Mocap, finish_mocap
from .npz_read import read_npz
from .units_axes import to_y_up


def _default_model():
    return OpenBody.load()


def is_smpl_family(model) -> bool:
    """True for SMPL/SMPL-H/SMPL-X models (``SMPLFamilyBody`` has ``family``; names 'smpl*')."""
    return hasattr(model, "family") or str(getattr(model, "name", "")).lower().startswith("smpl")


def read_amass_npz(path) -> dict:
    """The arrays of an AMASS file, checked: poses (T,66), trans (T,3), betas (10,), fps, gender."""
    path = Path(path)
    data = read_npz(path, ("poses", "trans", "betas", "mocap_framerate", "mocap_frame_rate", "gender"),
                    max_bytes=256 * 2**20, skip_objects=("gender",), what="AMASS motion file")
    for key in ("poses", "trans"):
        if key not in data:
            raise ShapeMoveError(f"{path}: AMASS file has no {key!r} array (keys: {', '.join(data)})")
    poses = np.asarray(data["poses"], dtype=np.float64)
    trans = np.asarray(data["trans"], dtype=np.float64)
    if poses.ndim != 2 or poses.shape[1] < 3 * NUM_BODY_JOINTS or len(poses) < 1:
        raise ShapeMoveError(f"{path}: 'poses' must be (T, >=66), got {poses.shape}")
    if trans.shape != (len(poses), 3):
        raise ShapeMoveError(f"{path}: 'trans' must be ({len(poses)}, 3), got {trans.shape}")
    check_joint_frames(len(poses), NUM_BODY_JOINTS, path, "AMASS clip")
    fps = data.get("mocap_framerate", data.get("mocap_frame_rate"))
    if fps is None:
        raise ShapeMoveError(f"{path}: AMASS file has no 'mocap_framerate'")
    fps = float(np.asarray(fps).reshape(-1)[0])
    betas = np.zeros(10)
    if "betas" in data:
        b = np.asarray(data["betas"], dtype=np.float64).reshape(-1)[:10]
        betas[: len(b)] = b
    if not all(np.all(np.isfinite(a)) for a in (poses, trans, betas)) or not np.isfinite(fps):
        raise ShapeMoveError(f"{path}: AMASS arrays hold NaN or inf")
    gender = str(np.asarray(data["gender"]).reshape(-1)[0]) if "gender" in data else "neutral"
    return {"poses": poses[:, : 3 * NUM_BODY_JOINTS], "trans": trans, "betas": betas, "fps": fps, "gender": gender}


def load_amass(path, body_model=None, betas="auto") -> Mocap:
    """Read an AMASS ``.npz`` into a Mocap on the 24 SMPL joints (hands unposed), metres, Y up."""
    d = read_amass_npz(path)
    model = body_model if body_model is not None else _default_model()
    use = betas if isinstance(betas, bool) else is_smpl_family(model)
    shape = d["betas"] if use else np.zeros(10)
    T = len(d["poses"])
    aa = np.zeros((T, 24, 3))
    aa[:, :NUM_BODY_JOINTS] = d["poses"].reshape(T, NUM_BODY_JOINTS, 3)
    with torch.no_grad():
        rest = model.rest_joints(torch.as_tensor(shape, dtype=torch.float32)[None])[0].double().numpy()  # (24,3)
    rot = axis_angle_to_matrix(aa)                                                              # (T,24,3,3)
    posed, _ = forward_kinematics(rot, rest, PARENTS)
    positions = posed + d["trans"][:, None]                # AMASS world, Z up
    R = to_y_up("Z")
    rotations = rot.copy()
    rotations[:, 0] = R @ rotations[:, 0]                  # the model's rest frame is already Y up
    offsets = bone_offsets(rest, PARENTS)
    mocap = finish_mocap(JOINT_NAMES, PARENTS, offsets, positions @ R.T, d["fps"], str(path),
                         rotations=rotations, unit="m", scale=1.0, up_axis="Y", subject=Path(path).parent.name,
                         meta={"gender": d["gender"], "betas": d["betas"], "betas_used": bool(use)})
    mocap.up_axis = "Z"
    return mocap
