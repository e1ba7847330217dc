"""Synthetic humanoid skeletons and BVH text for the mocap-reader tests (not a test module).

SMPL_REST: approximate neutral SMPL rest joints (22,3), metres, Y up, facing +Z, left at +X,
lifted so the ball of the foot is 0.03 m above the floor.
"""
from __future__ import annotations

import numpy as np

SMPL_REST = np.array([
    [0.000, 0.000, 0.000], [0.070, -0.091, 0.000], [-0.070, -0.091, 0.000], [0.000, 0.115, -0.010],
    [0.104, -0.452, 0.010], [-0.104, -0.452, 0.010], [0.000, 0.248, 0.000], [0.088, -0.850, -0.030],
    [-0.088, -0.850, -0.030], [0.000, 0.297, 0.020], [0.119, -0.906, 0.090], [-0.119, -0.906, 0.090],
    [0.000, 0.514, -0.010], [0.077, 0.424, 0.000], [-0.077, 0.424, 0.000], [0.005, 0.575, 0.030],
    [0.173, 0.452, -0.010], [-0.173, 0.452, -0.010], [0.433, 0.440, -0.030], [-0.433, 0.440, -0.030],
    [0.681, 0.444, -0.030], [-0.681, 0.444, -0.030],
]) + np.array([0.0, 0.936, 0.0])

# Mixamo names for SMPL joints (Spine/Spine1/Spine2 stand at spine1/2/3)
MIXAMO = {
    "Hips": 0, "LeftUpLeg": 1, "RightUpLeg": 2, "Spine": 3, "LeftLeg": 4, "RightLeg": 5, "Spine1": 6,
    "LeftFoot": 7, "RightFoot": 8, "Spine2": 9, "LeftToeBase": 10, "RightToeBase": 11, "Neck": 12,
    "LeftShoulder": 13, "RightShoulder": 14, "Head": 15, "LeftArm": 16, "RightArm": 17,
    "LeftForeArm": 18, "RightForeArm": 19, "LeftHand": 20, "RightHand": 21,
}
MIXAMO_PARENT = {
    "LeftUpLeg": "Hips", "RightUpLeg": "Hips", "Spine": "Hips", "LeftLeg": "LeftUpLeg", "RightLeg": "RightUpLeg",
    "Spine1": "Spine", "LeftFoot": "LeftLeg", "RightFoot": "RightLeg", "Spine2": "Spine1",
    "LeftToeBase": "LeftFoot", "RightToeBase": "RightFoot", "Neck": "Spine2", "LeftShoulder": "Spine2",
    "RightShoulder": "Spine2", "Head": "Neck", "LeftArm": "LeftShoulder", "RightArm": "RightShoulder",
    "LeftForeArm": "LeftArm", "RightForeArm": "RightArm", "LeftHand": "LeftForeArm", "RightHand": "RightForeArm",
}


def mixamo_skeleton(prefix: str = "mixamorig:"):
    """(names, parents, rest world positions (J,3) metres Y up) of a Mixamo-named humanoid whose
    joints stand exactly on SMPL_REST, in a parent-before-child order."""
    order = ["Hips"]
    while len(order) < len(MIXAMO):
        for n, p in MIXAMO_PARENT.items():
            if p in order and n not in order:
                order.append(n)
    parents = [-1] + [order.index(MIXAMO_PARENT[n]) for n in order[1:]]
    pos = np.array([SMPL_REST[MIXAMO[n]] for n in order])
    return [prefix + n for n in order], np.array(parents), pos


def bvh_text(names, parents, rest, motion, frame_time=1 / 30, root_channels=6):
    """BVH text: offsets from rest positions (J,3) in file units, root with 6 channels (ZXY) and
    3 rotation channels (ZXY) elsewhere; ``motion`` (T, C) channel values."""
    children = {i: [j for j in range(len(names)) if parents[j] == i] for i in range(len(names))}
    lines = ["HIERARCHY"]

    def emit(j, depth):
        pad = "  " * depth
        off = rest[j] - (rest[parents[j]] if parents[j] >= 0 else 0)
        lines.append(f"{pad}{'ROOT' if parents[j] < 0 else 'JOINT'} {names[j]}")
        lines.append(pad + "{")
        lines.append(f"{pad}  OFFSET {off[0]:.6f} {off[1]:.6f} {off[2]:.6f}")
        if parents[j] < 0:
            lines.append(f"{pad}  CHANNELS {root_channels} Xposition Yposition Zposition Zrotation Xrotation Yrotation")
        else:
            lines.append(f"{pad}  CHANNELS 3 Zrotation Xrotation Yrotation")
        for c in children[j]:
            emit(c, depth + 1)
        if not children[j]:
            lines.extend([f"{pad}  End Site", pad + "  {", f"{pad}    OFFSET 0 0 0.02", pad + "  }"])
        lines.append(pad + "}")

    emit(0, 0)
    lines += ["MOTION", f"Frames: {len(motion)}", f"Frame Time: {frame_time:.6f}"]
    lines += [" ".join(f"{v:.6f}" for v in row) for row in motion]
    return "\n".join(lines) + "\n"


def still_motion(rest_root, num_joints, frames):
    """(T, 6 + 3*(J-1)) channels holding the rest pose with the root at ``rest_root``."""
    m = np.zeros((frames, 6 + 3 * (num_joints - 1)))
    m[:, :3] = rest_root
    return m
