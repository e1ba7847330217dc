"""The SMPL 24-joint skeleton: names, kinematic tree and the 22-joint HumanML3D subset.

Coordinate convention used everywhere in ShapeMove: metres, Y up, the body in its rest pose
faces +Z, left side of the body at +X (as SMPL and HumanML3D).
"""
import numpy as np

JOINT_NAMES = [
    "pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2",
    "left_ankle", "right_ankle", "spine3", "left_foot", "right_foot", "neck",
    "left_collar", "right_collar", "head", "left_shoulder", "right_shoulder",
    "left_elbow", "right_elbow", "left_wrist", "right_wrist", "left_hand", "right_hand",
]
NUM_JOINTS = 24
NUM_BODY_JOINTS = 22  # HumanML3D uses the first 22 (no hands)

PARENTS = np.array(
    [-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 20, 21],
    dtype=np.int64,
)

JOINT_INDEX = {name: i for i, name in enumerate(JOINT_NAMES)}

# HumanML3D conventions (indices into the 22 body joints)
FOOT_LEFT = [7, 10]    # left ankle, left foot
FOOT_RIGHT = [8, 11]   # right ankle, right foot
FOOT_JOINTS = [7, 8, 10, 11]  # left ankle, right ankle, left foot, right foot: contacts and floor height
FACE_JOINTS = [2, 1, 17, 16]  # r_hip, l_hip, r_shoulder, l_shoulder: defines the facing direction

# Bones of the 22-joint body as (parent, child) pairs, used by bone-length losses and metrics.
BODY_BONES = [(int(PARENTS[j]), j) for j in range(1, NUM_BODY_JOINTS)]
