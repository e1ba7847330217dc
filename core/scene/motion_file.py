"""The motion file (``.npz``) that the generator writes and the Blender side reads.

Keys: ``joints`` (T,22,3) metres Y-up, ``betas`` (10,), ``poses`` (T,24,3) axis-angle local
rotations (SMPL convention, relative to the body's rest pose), ``transl`` (T,3) root offset as in
``BodyModel.forward`` (posed joints = FK(rest joints) + transl), ``fps``, ``body_model`` (id such as
"openbody-v1"); optional ``prompt`` (str), ``tokens`` and ``features`` (arrays), ``network_joints``
(T,22,3: the joints the SA-VAE decoded, before IK and grounding) and ``contacts`` (T,4 uint8: foot
contacts of joints 7, 8, 10, 11 that were planted), with ``contacts_measured`` (uint8 1) when those
came from the source mocap (retargeting) rather than the decoder: re-decoding plants them again.
Animation extras (``core/generation``, docs/animation.md): ``loop_advance`` (3,) float32, the root's
travel per cycle of a looping motion (frame T continues as frame 0 moved by it); ``segment_bounds``
(S,2) int32 [start, end) frames and ``segment_prompts`` (one str, the S prompts joined by newlines)
of a timeline of prompts.

A motion file is self-consistent: ``joints`` are the body's joints posed by (betas, poses, transl)
(``make_motion`` computes them; ``check_consistent`` verifies it), which is what the rig plays.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..body.skeleton import NUM_BODY_JOINTS, NUM_JOINTS
from ..errors import ShapeMoveError
from ..io.npz_read import read_npz


@dataclass
class Motion:
    joints: np.ndarray   # (T,22,3)
    betas: np.ndarray    # (10,)
    poses: np.ndarray    # (T,24,3)
    transl: np.ndarray   # (T,3)
    fps: float
    body_model: str
    prompt: str | None = None
    tokens: np.ndarray | None = None
    features: np.ndarray | None = None
    network_joints: np.ndarray | None = None
    contacts: np.ndarray | None = None
    contacts_measured: bool = False         # contacts came from the source mocap (retargeting), not the decoder
    loop_advance: np.ndarray | None = None  # (3,) root travel per cycle of a loop (frame T = frame 0 + it)
    segment_bounds: np.ndarray | None = None  # (S,2) [start, end) frames of a timeline's segments
    segment_prompts: list[str] | None = None  # the S prompts of those segments
    # run-time facts of a generated motion, not stored in the file
    ik_error_cm: float | None = None        # decode: mean IK error of the planted joints
    shape_source: str | None = None         # generate: "[BETA] head", "measurements" or "given"
    warnings: list[str] = field(default_factory=list)  # generate: the prompt check's warnings
    prompt_check: object | None = None      # generate: generation.prompts' check of the prompt

    @property
    def num_frames(self) -> int:
        return int(self.poses.shape[0])


def make_motion(body, poses, transl, betas, fps: float = 20.0, prompt: str | None = None, **extra) -> Motion:
    """Motion for ``body`` (a BodyModel): joints computed with ``body.forward``.

    poses (T,24,3) axis-angle, transl (T,3), betas (10,)."""
    import torch

    poses = np.asarray(poses, dtype=np.float32)
    transl = np.asarray(transl, dtype=np.float32)
    betas = np.asarray(betas, dtype=np.float32).reshape(-1)
    from ..body.kinematics import posed_joints   # FK only, in windows: no mesh (memory bounded by the window)

    with torch.no_grad():
        joints = posed_joints(body, betas, poses, transl)
    m = Motion(joints=joints[:, :NUM_BODY_JOINTS].numpy(), betas=betas, poses=poses, transl=transl,
               fps=float(fps), body_model=str(body.name), prompt=prompt, **extra)
    validate(m)
    return m


def validate(m: Motion) -> None:
    T = m.poses.shape[0] if m.poses.ndim else 0
    checks = [
        (m.poses.shape == (T, NUM_JOINTS, 3) and T > 0, f"poses must be (T,{NUM_JOINTS},3) with T > 0, got {m.poses.shape}"),
        (m.transl.shape == (T, 3), f"transl must be ({T},3), got {m.transl.shape}"),
        (m.joints.shape == (T, NUM_BODY_JOINTS, 3), f"joints must be ({T},{NUM_BODY_JOINTS},3), got {m.joints.shape}"),
        (m.betas.shape == (10,), f"betas must have 10 values, got shape {m.betas.shape}"),
        (np.isfinite(m.fps) and m.fps > 0, f"fps must be positive, got {m.fps}"),
        (bool(m.body_model), "body_model id is empty"),
    ]
    for ok, message in checks:
        if not ok:
            raise ShapeMoveError(f"bad motion: {message}")
    for name in ("poses", "transl", "betas"):
        if not np.isfinite(getattr(m, name)).all():
            raise ShapeMoveError(f"bad motion: {name} contains NaN or infinite values")
    if m.network_joints is not None and (m.network_joints.shape != (T, NUM_BODY_JOINTS, 3)
                                         or not np.isfinite(m.network_joints).all()):
        raise ShapeMoveError(f"bad motion: network_joints must be finite ({T},{NUM_BODY_JOINTS},3), "
                             f"got {m.network_joints.shape}")
    if m.contacts is not None and m.contacts.shape != (T, 4):
        raise ShapeMoveError(f"bad motion: contacts must be ({T},4), got {m.contacts.shape}")
    if m.loop_advance is not None and (np.shape(m.loop_advance) != (3,) or not np.isfinite(m.loop_advance).all()):
        raise ShapeMoveError(f"bad motion: loop_advance must be 3 finite numbers, got shape {np.shape(m.loop_advance)}")
    if m.segment_bounds is not None:
        b = np.asarray(m.segment_bounds)
        ok = (b.ndim == 2 and b.shape[1] == 2 and len(b) >= 1 and b[0, 0] == 0 and b[-1, 1] == T
              and (b[:, 1] > b[:, 0]).all() and (b[1:, 0] == b[:-1, 1]).all())
        if not ok:
            raise ShapeMoveError(f"bad motion: segment_bounds must be (S,2) consecutive [start, end) frames "
                                 f"covering 0..{T}, got {b.tolist() if b.size < 40 else b.shape}")
        if m.segment_prompts is None or len(m.segment_prompts) != len(b):
            raise ShapeMoveError(f"bad motion: {len(b)} segments need as many segment_prompts")


def fk_joints(body, m: Motion) -> np.ndarray:
    """(T,22,3) joints of ``body`` posed by the motion's (betas, poses, transl)."""
    import torch

    from ..body.kinematics import posed_joints

    with torch.no_grad():
        return posed_joints(body, m.betas, m.poses, m.transl)[:, :NUM_BODY_JOINTS].numpy()


def check_consistent(body, m: Motion, tol: float = 1e-3) -> float:
    """Largest distance (m) between the motion's ``joints`` and FK of its pose on ``body``;
    ShapeMoveError when above ``tol`` (the file's joints would not be what the rig plays)."""
    err = float(np.abs(fk_joints(body, m) - m.joints).max()) if m.num_frames else 0.0
    if not err <= tol:
        raise ShapeMoveError(f"bad motion: joints differ from the posed body by {err * 100:.2f} cm "
                             f"(more than {tol * 100:.2f} cm); rebuild them with make_motion")
    return err


def save_motion(path, m: Motion) -> Path:
    """Write ``m`` atomically to ``path`` (.npz)."""
    validate(m)
    path = Path(path)
    arrays = dict(joints=m.joints, betas=m.betas, poses=m.poses, transl=m.transl,
                  fps=np.float32(m.fps), body_model=np.str_(m.body_model))
    if m.prompt is not None:
        arrays["prompt"] = np.str_(m.prompt)
    for name in ("tokens", "features", "network_joints", "contacts"):
        if getattr(m, name) is not None:
            arrays[name] = np.asarray(getattr(m, name))
    if m.contacts is not None and m.contacts_measured:
        arrays["contacts_measured"] = np.uint8(1)
    if m.loop_advance is not None:
        arrays["loop_advance"] = np.asarray(m.loop_advance, np.float32)
    if m.segment_bounds is not None:
        arrays["segment_bounds"] = np.asarray(m.segment_bounds, np.int32)
        arrays["segment_prompts"] = np.str_("\n".join(m.segment_prompts))

    with atomic_path(path) as tmp:  # read-only folder, a parent that is a file, disk full: a sentence, no *.tmp
        with open(tmp, "wb") as f:
            np.savez(f, **arrays)
    return path


def load_motion(path) -> Motion:
    """Read and validate a motion file; ShapeMoveError names what is missing or malformed."""
    path = Path(path)
    if not path.is_file():
        raise ShapeMoveError(f"motion file not found: {path}")

    try:  # headers checked and sizes capped before allocating; pickled arrays refused
        data = read_npz(path, max_bytes=512 * 2**20, what="motion file")
    except ShapeMoveError as exc:
        raise ShapeMoveError(f"cannot read motion file {exc}") from None
    missing = [k for k in ("joints", "betas", "poses", "transl", "fps", "body_model") if k not in data]
    if missing:
        raise ShapeMoveError(f"motion file {path} lacks {', '.join(missing)}")
    for key, kinds in (("loop_advance", "iuf"), ("segment_bounds", "iu")):
        if key in data and data[key].dtype.kind not in kinds:
            raise ShapeMoveError(f"motion file {path}: {key} must be numbers, got {data[key].dtype}")
    m = Motion(joints=data["joints"].astype(np.float32), betas=data["betas"].astype(np.float32).reshape(-1),
               poses=data["poses"].astype(np.float32), transl=data["transl"].astype(np.float32),
               fps=float(data["fps"]), body_model=str(data["body_model"]),
               prompt=str(data["prompt"]) if "prompt" in data else None,
               tokens=data.get("tokens"), features=data.get("features"),
               network_joints=data["network_joints"].astype(np.float32) if "network_joints" in data else None,
               contacts=data["contacts"].astype(np.uint8) if "contacts" in data else None,
               contacts_measured="contacts" in data and "contacts_measured" in data
               and data["contacts_measured"].shape == () and bool(data["contacts_measured"]),
               loop_advance=data["loop_advance"].astype(np.float32).reshape(-1) if "loop_advance" in data else None)
    if "segment_bounds" in data:
        if "segment_prompts" not in data or data["segment_prompts"].shape != ():
            raise ShapeMoveError(f"motion file {path} has segment_bounds without segment_prompts")
        m.segment_bounds = np.asarray(data["segment_bounds"]).astype(np.int64)
        m.segment_prompts = str(data["segment_prompts"]).split("\n")
    validate(m)
    return m
