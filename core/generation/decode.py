"""Motion tokens + body shape -> a Motion on the body model (the last step of generation,
retargeting and re-decoding for a new body)."""
from __future__ import annotations

import numpy as np
import torch

from ..body.plant import BODY_SMOOTH, contacts_from_features, plant_motion
from ..constants import FPS
from ..errors import ShapeMoveError
from ..geometry.rotations import matrix_to_axis_angle
from ..motion.features import joints_from_features
from ..scene.motion_file import Motion, make_motion
from .decoded_joints import decoded_joints



def check_betas(betas) -> np.ndarray:
    b = np.asarray(betas, dtype=np.float32).reshape(-1)
    if b.shape != (10,) or not np.isfinite(b).all():
        raise ShapeMoveError(f"betas must be 10 finite values, got shape {b.shape}")
    return b


@torch.no_grad()
def decode_features(codes: list[int], vae, betas) -> torch.Tensor:
    """Motion tokens + betas (10,) -> the SA-VAE's (T, 263) shape-aware features (denormalized)."""
    if not codes:
        raise ShapeMoveError("no motion tokens to decode")
    b = torch.as_tensor(check_betas(betas))[None]
    idx = torch.as_tensor(codes, dtype=torch.long)[None]
    return vae.denormalize(vae.decode_tokens_long(idx, b))[0]


def decode_tokens(codes: list[int], vae, body, betas, ik_refine_iters: int = 10, prompt: str | None = None,
                  contacts=None) -> Motion:
    """Motion tokens + betas (10,) -> Motion on ``body``: SA-VAE ``decode_long`` with the body's
    shape; its joints: the decoded positions of the legs, the upper body posed from the decoded
    rotations (``decoded_joints``: they carry the asked-for action better than the decoded
    positions); then ``plant.plant_motion``: the feet
    the decoder's contact channels mark are planted (one fixed point per contact run, soles on
    y = 0), IK onto the body, and the posed mesh grounded frame by frame on its soles. The
    Motion's ``joints`` are FK of its pose (what the rig plays); the joints it was planted from
    are kept as ``network_joints``. ``contacts`` (>= T,4) known foot contacts (retargeting: the
    source motion's) are planted instead of the decoder's channels, as measured contacts (no
    gating, flights kept); a retargeted take is played from the decoded joint positions, the
    channel its codes were searched against (``code_search``)."""
    betas = check_betas(betas)
    feats = decode_features(codes, vae, betas)
    known = contacts is not None
    if known:
        with torch.no_grad():
            joints = joints_from_features(feats.double()).float().numpy()
        contacts = np.asarray(contacts)
        if contacts.ndim != 2 or contacts.shape[1] != 4 or len(contacts) < len(joints):
            raise ShapeMoveError(f"known contacts must be (>= {len(joints)}, 4), got shape {contacts.shape}")
        contacts = contacts[:len(joints)]
    else:
        joints = decoded_joints(feats, body, betas).astype(np.float32)
        contacts = contacts_from_features(feats.numpy())
    return motion_from_joints(body, betas, joints, contacts, ik_refine_iters, prompt=prompt, known_contacts=known,
                              tokens=np.asarray(codes, np.int32), features=feats.numpy().astype(np.float32))


def redecode(motion: Motion, vae, body, betas, ik_refine_iters: int = 10) -> Motion:
    """A motion's tokens decoded for another body (``betas``): feet stay planted and bones take the
    new lengths. A retargeted motion plants its source's measured contacts again
    (``contacts_measured``); a generated one plants what the decoder predicts for the new body."""
    if motion.tokens is None or len(motion.tokens) == 0:
        raise ShapeMoveError("this motion has no tokens to re-decode (it was not generated or retargeted)")
    known = motion.contacts if motion.contacts_measured else None
    return decode_tokens([int(t) for t in motion.tokens], vae, body, betas, ik_refine_iters, prompt=motion.prompt,
                         contacts=known)


def motion_from_joints(body, betas, joints, contacts, ik_refine_iters: int = 10, prompt: str | None = None,
                       known_contacts: bool = False, smooth: float = BODY_SMOOTH, **extra) -> Motion:
    """(T,22,3) joint positions + (T,4) foot contacts of joints 7, 8, 10, 11 -> self-consistent
    Motion on ``body`` with ``betas``: the body but the feet smoothed over ``BODY_SMOOTH`` frames
    against decoder jitter (``plant.smooth_body``: the zero-moment point follows the centre of mass's
    acceleration), contacts planted, mesh grounded (``plant.plant_motion``); ``known_contacts``:
    ``contacts`` are measured (not predicted): planted without gating, long flights kept;
    ``smooth``: that smoothing's sigma (0 for captured joints, which carry no decoder jitter);
    ``extra``: tokens, features."""
    planted = plant_motion(body, betas, joints, contacts, refine_iters=ik_refine_iters, smooth=smooth, **(
        {"gate": False, "max_flight": None} if known_contacts else {}))
    poses = matrix_to_axis_angle(planted.rotations).astype(np.float32)
    m = make_motion(body, poses, planted.transl, betas, fps=float(FPS), prompt=prompt,
                    network_joints=np.asarray(joints, np.float32), contacts=planted.contacts,
                    contacts_measured=bool(known_contacts), **extra)
    m.ik_error_cm = planted.ik_error_cm
    return m
