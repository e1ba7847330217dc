"""Gait measures of a motion's joints: root speed, velocity agreement, cadence, stride length.

All take (T,22,3) joints in metres, Y up, at ``fps`` frames per second (20 after import).

- ``mean_speed``: the root's (pelvis, joint 0) horizontal path length over the clip's duration (m/s);
- ``velocity_correlation``: Pearson correlation of two motions' per-frame horizontal root
  velocities (x and z pooled, each motion's mean velocity removed first), frame for frame: 1 when
  one is a scaled copy of the other, ~0 when the within-step surges do not line up;
- ``cycle_frequency``: gait cycles (strides, two steps) per second: the dominant frequency of the
  ankles' fore-aft separation (left ankle minus right, along the body's facing direction); it swings
  once per cycle whatever the root does, so it does not depend on the root's travel;
- ``swing`` : the ankles' fore-aft separation's amplitude (sqrt(2) x its standard deviation, m):
  how far the feet reach apart, ahead and behind, whatever the root does;
- ``cadence`` = 2 x ``cycle_frequency`` (steps per second);
- ``stride_length`` = ``mean_speed`` / ``cycle_frequency`` (metres per cycle);
- ``leg_length(body, betas)``: the rest pelvis height above the lowest foot joint, the leg
  length the dataset builder scales a motion's root path by (``data.build.ClipProcessor.stride_scale``).
"""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from ..motion.root_speed import _joints, mean_speed, root_velocity  # noqa: F401  (the root's speed, one definition)
from ..motion.skeleton_ops import facing_directions

MIN_HZ, MAX_HZ = 0.3, 4.0   # gait cycles per second searched (a slow walk ~0.5, a sprint ~2)
PAD = 8192                   # FFT length (zero-padded): 0.0024 Hz resolution at 20 fps


def velocity_correlation(a, b, fps: float = FPS) -> float:
    """Pearson correlation of the per-frame horizontal root velocities of two motions of the same
    frames (the shorter length is used); NaN when either does not vary."""
    va, vb = root_velocity(a, fps), root_velocity(b, fps)
    n = min(len(va), len(vb))
    va, vb = va[:n] - va[:n].mean(0), vb[:n] - vb[:n].mean(0)
    den = np.sqrt((va ** 2).sum() * (vb ** 2).sum())
    return float((va * vb).sum() / den) if den > 1e-12 else float("nan")


def ankle_separation(joints) -> np.ndarray:
    """(T,) left ankle minus right ankle along the body's facing direction (m): positive when the
    left foot is ahead."""
    j = _joints(joints)
    fwd = facing_directions(j)[:, [0, 2]]
    fwd /= np.linalg.norm(fwd, axis=-1, keepdims=True).clip(1e-9)
    return ((j[:, 7, [0, 2]] - j[:, 8, [0, 2]]) * fwd).sum(-1)


def swing(joints) -> float:
    """Amplitude of the ankles' fore-aft separation (m): sqrt(2) x its standard deviation (the
    amplitude of a sine), a step length's measure that does not look at the root."""
    return float(np.sqrt(2.0) * ankle_separation(joints).std())


def min_cycle_frames(fps: float = FPS) -> int:
    """Frames ``cycle_frequency`` needs: 1.5 cycles of the slowest gait searched (100 at 20 fps)."""
    return int(np.ceil(1.5 * fps / MIN_HZ))


def cycle_frequency(joints, fps: float = FPS) -> float:
    """Gait cycles per second: the peak of the ankle separation's spectrum between MIN_HZ and
    MAX_HZ (Hann window, zero-padded). Needs ``min_cycle_frames`` frames."""
    s = ankle_separation(joints)
    if len(s) < min_cycle_frames(fps):
        raise ShapeMoveError(f"too short to measure the gait cycle ({len(s)} frames; need "
                             f"{min_cycle_frames(fps)} at {fps:g} fps)")
    s = (s - s.mean()) * np.hanning(len(s))
    spec = np.abs(np.fft.rfft(s, n=max(PAD, len(s))))
    hz = np.fft.rfftfreq(max(PAD, len(s)), 1.0 / fps)
    band = (hz >= MIN_HZ) & (hz <= MAX_HZ)
    return float(hz[band][np.argmax(spec[band])])


def cadence(joints, fps: float = FPS) -> float:
    """Steps per second (two per gait cycle)."""
    return 2.0 * cycle_frequency(joints, fps)


def stride_length(joints, fps: float = FPS) -> float:
    """Metres travelled per gait cycle: mean speed / cycle frequency."""
    return mean_speed(joints, fps) / cycle_frequency(joints, fps)


def leg_length(body, betas) -> float:
    """The rest pelvis height of ``body`` with ``betas`` above its lowest foot joint (m)."""
    import torch

    b = np.asarray(betas, dtype=np.float32).reshape(1, -1)
    with torch.no_grad():
        r = body.rest_joints(torch.as_tensor(b))[0].numpy()
    return float(r[0, 1] - min(r[7, 1], r[8, 1], r[10, 1], r[11, 1]))
