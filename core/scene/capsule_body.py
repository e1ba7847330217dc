"""A small procedural body model ("capsule-v1"): one open tube per SMPL bone, ~800 vertices.

It is a genuine linear BodyModel (template + shapedirs, a joint regressor linear in the vertices,
LBS weights), just coarse: used by the Blender tests and benchmarks, which need a body that is
fast to build and whose shape directions have known meanings:
beta_0 height (+6 %/unit, feet stay at y=0), beta_1 width (+6 %/unit), beta_2 limb girth,
beta_3 front-back depth, beta_4 leg length, beta_5 arm span, beta_6 torso girth, beta_7..9 small
smooth wobbles. Rest pose: T-pose, Y up, facing +Z, left at +X, feet at y = 0.
"""
from __future__ import annotations

import numpy as np

from ..body.model import BodyModel
from ..body.skeleton import JOINT_NAMES, PARENTS
from .bones import main_children

NAME = "capsule-v1"
SEGMENTS = 8
RINGS = 4

# SMPL-like rest joints (metres, Y up, facing +Z, left = +X), T-pose.
REST_JOINTS = np.array([
    [0.00, 0.93, 0.00], [0.09, 0.85, 0.00], [-0.09, 0.85, 0.00], [0.00, 1.04, -0.01],
    [0.10, 0.48, 0.005], [-0.10, 0.48, 0.005], [0.00, 1.17, 0.00], [0.11, 0.08, -0.03],
    [-0.11, 0.08, -0.03], [0.00, 1.23, 0.01], [0.12, 0.02, 0.10], [-0.12, 0.02, 0.10],
    [0.00, 1.45, -0.01], [0.07, 1.37, 0.00], [-0.07, 1.37, 0.00], [0.00, 1.52, 0.03],
    [0.17, 1.40, -0.01], [-0.17, 1.40, -0.01], [0.43, 1.39, -0.02], [-0.43, 1.39, -0.02],
    [0.68, 1.40, 0.00], [-0.68, 1.40, 0.00], [0.76, 1.40, 0.00], [-0.76, 1.40, 0.00],
])
RADIUS = {"pelvis": 0.13, "spine1": 0.13, "spine2": 0.14, "spine3": 0.14, "neck": 0.05, "head": 0.09,
          "left_hip": 0.08, "right_hip": 0.08, "left_knee": 0.06, "right_knee": 0.06,
          "left_ankle": 0.045, "right_ankle": 0.045, "left_foot": 0.04, "right_foot": 0.04,
          "left_collar": 0.05, "right_collar": 0.05}
TORSO = {"pelvis", "spine1", "spine2", "spine3"}


def _tube_ends(joints: np.ndarray) -> np.ndarray:
    """(24,3) end point of the tube that starts at each joint."""
    kids = main_children(joints)
    ends = np.zeros_like(joints)
    for j, k in enumerate(kids):
        if k is not None:
            ends[j] = joints[k]
        else:
            d = joints[j] - joints[PARENTS[j]]
            length = 0.2 if JOINT_NAMES[j] == "head" else max(0.5 * np.linalg.norm(d), 0.05)
            ends[j] = joints[j] + d / np.linalg.norm(d) * length
    return ends


def capsule_body() -> BodyModel:
    joints = REST_JOINTS
    ends = _tube_ends(joints)
    kids = main_children(joints)
    verts, centres, faces, weights, regressor_rings, torso = [], [], [], [], [], []
    phi = np.arange(SEGMENTS) * 2 * np.pi / SEGMENTS
    for j, name in enumerate(JOINT_NAMES):
        d = ends[j] - joints[j]
        d = d / np.linalg.norm(d)
        a = np.array([0.0, 0.0, 1.0]) if abs(d[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        u = np.cross(d, a)
        u /= np.linalg.norm(u)
        w = np.cross(d, u)
        r = RADIUS.get(name, 0.04)
        base = len(verts)
        for k, s in enumerate(np.linspace(0.0, 1.0, RINGS)):
            c = joints[j] + s * (ends[j] - joints[j])
            for p in phi:
                verts.append(c + r * (np.cos(p) * u + np.sin(p) * w))
                centres.append(c)
                row = np.zeros(len(JOINT_NAMES))
                blend = max(0.0, s - 0.5) if kids[j] is not None else 0.0
                row[j] = 1.0 - blend
                if blend:
                    row[kids[j]] = blend
                weights.append(row)
                torso.append(name in TORSO)
            if k + 1 < RINGS:
                for i in range(SEGMENTS):
                    a0, a1 = base + k * SEGMENTS + i, base + k * SEGMENTS + (i + 1) % SEGMENTS
                    faces += [(a0, a1, a1 + SEGMENTS), (a0, a1 + SEGMENTS, a0 + SEGMENTS)]
        regressor_rings.append(range(base, base + SEGMENTS))
    v = np.array(verts)
    offset = v - np.array(centres)
    torso = np.array(torso, dtype=np.float64)[:, None]
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    zero = np.zeros_like(x)
    dirs = [
        np.stack([zero, 0.06 * y, zero], -1),                                   # height
        np.stack([0.06 * x, zero, zero], -1),                                   # width
        0.1 * offset * (1 - torso),                                             # limb girth
        np.stack([zero, zero, 0.15 * offset[:, 2]], -1),                        # depth
        np.stack([zero, 0.05 * np.minimum(y - 0.9, 0.0), zero], -1),            # leg length
        np.stack([0.05 * np.sign(x) * np.maximum(np.abs(x) - 0.17, 0.0), zero, zero], -1),  # arm span
        0.12 * offset * torso,                                                  # torso girth
    ]
    for k in range(3):
        dirs.append(0.01 * np.stack([np.sin(3 * y + k), np.cos(2 * x + k), np.sin(4 * y + 2 * k)], -1))
    shapedirs = np.stack(dirs, -1)
    regressor = np.zeros((len(JOINT_NAMES), len(v)))
    for j, ring in enumerate(regressor_rings):
        regressor[j, list(ring)] = 1.0 / SEGMENTS
    return BodyModel(v, shapedirs, regressor, np.array(weights), np.array(faces), name=NAME)
