"""A body-like walking track for the tests that join and splice timelines (no model needed)."""
import numpy as np

from shapemove.core.generation.track import Track, rotate_y


def walk(T, speed, turn=0.0, seed=0):
    """A body-like track: a fixed 22-joint pose walking along +Z (turning ``turn`` rad a frame);
    ``speed`` and ``turn`` may be per-frame arrays."""
    rng = np.random.default_rng(seed)
    pose = rng.normal(scale=0.2, size=(22, 3))
    pose[:, 1] = np.abs(pose[:, 1]) + 0.1
    pose[0] = [0.0, 0.9, 0.0]
    pose[1], pose[2] = [0.1, 0.9, 0.0], [-0.1, 0.9, 0.0]      # hips across
    pose[16], pose[17] = [0.2, 1.4, 0.0], [-0.2, 1.4, 0.0]    # shoulders across
    yaw = np.cumsum(np.broadcast_to(turn, (T,))) - np.broadcast_to(turn, (T,))[0]
    speed = np.broadcast_to(speed, (T,))[:, None]
    pos = np.cumsum(np.stack([np.sin(yaw), np.zeros(T), np.cos(yaw)], 1) * speed, 0)
    joints = rotate_y(np.broadcast_to(pose, (T, 22, 3)), yaw) + pos[:, None]
    contacts = (np.arange(T)[:, None] // 10 % 2 == np.array([0, 0, 1, 1])).astype(np.uint8)
    return Track(joints, contacts)
