"""The decoder's joint track of a motion: what loop, path and speed edits work on before the feet
are planted again.

A generated Motion keeps the joints it was planted from (``network_joints``, Y up, before IK and
grounding: ``decoded_joints``, the upper body posed from the decoded rotations)
and the contacts it planted. The animation edits (``loop``, ``path_follow``, ``time_warp``,
``sequence``) change those joints and contacts and hand them to ``decode.motion_from_joints``
(``body/plant.py``: one fixed point per contact run, IK, grounding on the mesh soles), so every
edit ends with the feet re-planted instead of sliding. ``in_place`` is the exception: it moves the
finished pose (a treadmill has no fixed footholds).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import torch

from ..body.plant import EASE, MIN_EASE, anchor_track, contacts_from_features, eased, plant_motion
from ..constants import FPS
from ..geometry.rotations import matrix_to_axis_angle
from ..errors import ShapeMoveError
from ..motion.contacts import CONTACT_IDS, detect_contacts, runs
from ..motion.skeleton_ops import facing_directions, gaussian_smooth, heading_angles, smooth_directions
from ..scene.motion_file import Motion, make_motion
from .decode import decode_features
from .decoded_joints import decoded_joints

HEADING_SIGMA = 5.0   # frames: the body's heading without the hips' swing of each step
CENTRE_SIGMA = 5.0    # frames: the root's path without its sway


@dataclass
class Track:
    joints: np.ndarray     # (T,22,3) float64, metres, Y up
    contacts: np.ndarray   # (T,4) uint8 of joints 7, 8, 10, 11

    def __post_init__(self):
        self.joints = np.asarray(self.joints, np.float64)
        self.contacts = np.asarray(self.contacts, np.uint8)
        if self.joints.ndim != 3 or self.joints.shape[1:] != (22, 3) or len(self.joints) < 2:
            raise ShapeMoveError(f"a joint track needs (T>=2,22,3) joints, got {self.joints.shape}")
        if self.contacts.shape != (len(self.joints), 4):
            raise ShapeMoveError(f"a joint track needs ({len(self.joints)},4) contacts, got {self.contacts.shape}")

    def __len__(self) -> int:
        return len(self.joints)


def track_of(motion: Motion) -> Track:
    """The decoder's joints and planted contacts of ``motion``; a motion without them (e.g. read
    from mocap) gives its posed joints and contacts detected on them."""
    joints = motion.network_joints if motion.network_joints is not None else motion.joints
    contacts = motion.contacts if motion.contacts is not None else detect_contacts(joints, motion.fps)
    return Track(joints, contacts)


@torch.no_grad()
def decoded_track(codes: list[int], vae, body, betas) -> tuple[Track, np.ndarray]:
    """Motion codes + betas -> (the SA-VAE's joint track on ``body``: decoded positions for the legs,
    the upper body posed from the decoded rotations (``decoded_joints``); its (T,263) features)."""
    feats = decode_features(codes, vae, betas)
    joints = decoded_joints(feats, body, betas)
    f = feats.numpy().astype(np.float32)
    return Track(joints, contacts_from_features(f)), f


def fitted(track: Track, frames: int) -> Track:
    """``track`` cut to ``frames`` frames, or its last frame held to that length."""
    extra = frames - len(track)
    if extra <= 0:
        return Track(track.joints[:frames], track.contacts[:frames])
    return Track(np.concatenate([track.joints, np.repeat(track.joints[-1:], extra, 0)]),
                 np.concatenate([track.contacts, np.repeat(track.contacts[-1:], extra, 0)]))


def resample(track: Track, n: int, advance=None) -> Track:
    """``track`` resampled to ``n`` frames. Open: frame 0 and the last frame stay where they are.
    A loop (``advance`` (3,)): the ``n`` frames sample one cycle of ``len(track)`` frames, frame
    ``len(track)`` being frame 0 moved by ``advance``."""
    J, C = track.joints, track.contacts
    T = len(J)
    if advance is not None:
        J = np.concatenate([J, J[:1] + np.asarray(advance, np.float64)], 0)
        C = np.concatenate([C, C[:1]], 0)
        t = np.arange(n) * T / n
    else:
        t = np.linspace(0.0, T - 1, n)
    i0 = np.minimum(np.floor(t).astype(int), len(J) - 2)
    w = (t - i0)[:, None, None]
    joints = (1 - w) * J[i0] + w * J[i0 + 1]
    contacts = C[np.minimum(np.round(t).astype(int), len(C) - 1)]
    if advance is not None:
        contacts = C[np.round(t).astype(int) % T]
    return Track(joints, contacts)


def plant(body, betas, track: Track, ik_refine_iters: int = 10, prompt: str | None = None, **extra) -> Motion:
    """A track -> Motion on ``body`` with its contacts planted (``plant.plant_motion``, as
    ``decode.motion_from_joints``), then ``lock_stance``."""
    planted = plant_motion(body, betas, track.joints, track.contacts, refine_iters=ik_refine_iters)
    m = make_motion(body, matrix_to_axis_angle(planted.rotations).astype(np.float32), planted.transl, betas,
                    fps=float(FPS), prompt=prompt, network_joints=track.joints.astype(np.float32),
                    contacts=planted.contacts, **extra)
    m = lock_stance(m)
    m.ik_error_cm = planted.ik_error_cm
    return m


def replanted(motion: Motion, body, track: Track, ik_refine_iters: int = 10, measured: bool = False) -> Motion:
    """A generated motion after an edit of its track (a circle walked, a turn given back): planted
    again (``plant``), its features computed as the dataset builder computes a clip's (what the
    judges and the TMA read), and what generation said of it kept (body source, retrieved clips,
    part prompts, warnings, notes). Like every edit, it keeps no tokens: a new body plants it again
    by its own rotations on the contacts it is planted on here (``contacts_measured``:
    ``Motion.planted_take``, ``retarget.replant``), stride scaled by leg length, rather than
    re-decoding it. ``measured``: the track's contacts are a captured take's, planted as they are
    (``decode.motion_from_joints`` with known contacts, no smoothing)."""
    from ..motion.features import motion_features
    from .decode import motion_from_joints

    out = motion_from_joints(body, motion.betas, track.joints, track.contacts, ik_refine_iters, prompt=motion.prompt,
                             known_contacts=True, smooth=0.0) if measured else \
        plant(body, motion.betas, track, ik_refine_iters, prompt=motion.prompt)
    out.features = motion_features(out)
    out.contacts_measured = out.contacts is not None   # the contacts it is planted on: planted on again
    for key in ("shape_source", "retrieved_clips", "part_prompts", "warnings", "notes"):
        if hasattr(motion, key):
            setattr(out, key, getattr(motion, key))
    return out


def lock_stance(motion: Motion) -> Motion:
    """The planted feet held still by moving the whole body horizontally by millimetres.

    ``plant.pin_feet`` is a soft two-bone IK: a leg near full stretch (heel strike, push-off)
    stops short of its target, so a planted foot still drifts ~0.5 mm per frame. Here each frame
    with a contact is shifted in XZ by the mean offset of its planted joints from where their run
    is planted (``plant.anchor_track``: the run's mean, or its pieces' along a slide); frames without contact take the shift interpolated between their neighbours
    (so the body's path stays smooth), and the shift moves no faster in a frame than ``plant.EASE``
    of the pelvis's largest step (``plant.eased``). Rotations, heights and the contacts are unchanged."""
    c = np.asarray(motion.contacts).astype(bool) if motion.contacts is not None else None
    if c is None or not c.any():
        return motion
    J = np.asarray(motion.joints, np.float64)
    res = np.zeros((len(J), 4, 2))
    for k, joint in enumerate(CONTACT_IDS):
        for s, e in runs(c[:, k]):
            xz = J[s:e, joint][:, [0, 2]]
            res[s:e, k] = anchor_track(xz) - xz   # the run's point (its pieces' where it slides: plant.py)
    support = c.any(1)
    shift = (res * c[..., None]).sum(1) / np.maximum(c.sum(1), 1)[:, None]
    t = np.arange(len(J))
    shift = np.stack([np.interp(t, t[support], shift[support, i]) for i in range(2)], axis=1)
    fastest = float(np.linalg.norm(np.diff(J[:, 0], axis=0), axis=1).max()) if len(J) > 1 else 0.0
    shift = eased(shift, max(EASE * fastest, MIN_EASE))   # where the planted feet change, the shift
    # from one foot's miss to the other's spread over frames (at once, the body leapt 0.16 m in a frame)
    d = np.zeros((len(J), 3))
    d[:, [0, 2]] = shift
    out = dataclasses.replace(motion, transl=(motion.transl + d).astype(np.float32),
                              joints=(J + d[:, None]).astype(np.float32))
    out.warnings = list(motion.warnings)
    return out


def headings(joints) -> np.ndarray:
    """(T,) yaw of the body (0 facing +Z, +pi/2 facing +X), the step's hip swing smoothed away."""
    return heading_angles(smooth_directions(facing_directions(np.asarray(joints, np.float64)), HEADING_SIGMA))


def root_centre(joints) -> np.ndarray:
    """(T,2) XZ of the root (pelvis) with its sway smoothed away."""
    return gaussian_smooth(np.asarray(joints, np.float64)[:, 0, [0, 2]], CENTRE_SIGMA)


def travel(joints) -> np.ndarray:
    """(T,) distance (m) the smoothed root has travelled along its own path at each frame."""
    c = root_centre(joints)
    return np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))]


def motion_speed(motion_or_joints, fps: float = FPS) -> float:
    """Mean speed (m/s) of the smoothed root along its own course."""
    joints = motion_or_joints.joints if isinstance(motion_or_joints, Motion) else motion_or_joints
    s = travel(joints)
    return float(s[-1] / max(len(s) - 1, 1) * fps)


def yaw_matrix(angle: float) -> np.ndarray:
    """(3,3) rotation by ``angle`` about +Y, the one ``rotate_y`` applies to points (a heading of
    ``headings`` grows by ``angle``)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def smoothstep(x) -> np.ndarray:
    """0 -> 1 over x in [0, 1] with zero slope at both ends (3x^2 - 2x^3), 0 before, 1 after."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def rotate_y(points, angle) -> np.ndarray:
    """Rotate (...,3) points about +Y by ``angle`` (per leading frame when an array)."""
    a = np.asarray(angle, np.float64)
    c, s = np.cos(a), np.sin(a)
    p = np.asarray(points, np.float64)
    if a.ndim:
        c, s = c.reshape(c.shape + (1,) * (p.ndim - 2)), s.reshape(s.shape + (1,) * (p.ndim - 2))
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    return np.stack([c * x + s * z, y, -s * x + c * z], axis=-1)
