"""Reader for DeepMimic reference motions (Peng et al., "DeepMimic", ACM TOG 2018; MIT licence).

A DeepMimic motion is a JSON file ``{"Loop": "wrap" | "none", "Frames": [[...], ...]}`` (plus
optional keys the reader ignores). Each frame holds 44 numbers for the 13-body ``humanoid3d``
character::

    duration (s, time to the next frame; the last frame's is ignored),
    root position (3, metres, world), root rotation (quaternion w, x, y, z, world),
    chest, neck, right hip (quaternions, local), right knee (1 angle, rad),
    right ankle, right shoulder (quaternions), right elbow (1 angle),
    left hip (quaternion), left knee (angle), left ankle, left shoulder (quaternions), left elbow (angle)

The skeleton is DeepMimic's ``data/characters/humanoid3d.txt`` (``HUMANOID3D`` below: joint
attachments in metres). Its frame: Y up, the character faces +X and its right side is at +Z;
knees and elbows are revolute joints about their local Z axis (knee angles <= 0 bend the shin
backward, elbow angles >= 0 bend the forearm forward). Checked on the shipped clips: the walk's
root is 0.85 m above the floor with straight-ish legs (hip -> ankle 0.83 m + 5 cm of foot box), the
soles touch y = 0 within ~1 cm, and the walk travels +X.

The reader does forward kinematics of the quaternions on that skeleton, adds three virtual points
the SMPL body needs and the humanoid lacks (head above the neck joint, ball of each foot inside
the foot box; collars and spine joints are interpolated by the ``deepmimic`` rig of
``rig_map``), and turns everything into ShapeMove's frame (faces +Z, left at +X). Frames with
uneven durations are resampled to the median frame time (quaternions by slerp).
``Loop: wrap`` clips shorter than ``loop_min_seconds`` are repeated by whole cycles, each cycle
continuing from where the previous one ended (position and heading), as DeepMimic plays them.

Memory is bounded: files over ``MAX_BYTES`` or ``MAX_FRAMES`` are refused before parsing the
frames into arrays. Every malformed file raises ShapeMoveError naming the problem.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from .limits import MAX_SECONDS, check_joint_frames, read_text
from .mocap_clip import finish_mocap
from ..geometry.fk import forward_kinematics, joints_from_offsets
from ..geometry.rotations import axis_rotation, matrix_to_quaternion, quaternion_to_matrix, slerp, yaw_matrix

MAX_BYTES = 16 * 2**20           # the largest shipped clip is 3.6 MB; JSON lists cost ~10x the text in memory
MAX_FRAMES = 200_000             # ~28 min at 120 fps
MAX_ABS = 1.0e4                  # metres / radians: anything larger is not a motion
FRAME_VALUES = 44
LOOP_MIN_SECONDS = 1.5           # wrap clips shorter than this are repeated by whole cycles
MAX_CYCLES = 16

# (name, parent, attachment in the parent's frame (m), kind, first value in a frame row)
# kind: "root" | "quat" | "knee" (revolute about local Z) | "fixed" | "virtual" (a point, no channel)
HEAD_POINT = (0.02, 0.09, 0.0)    # SMPL head joint: ~9 cm above the neck base (OpenBody: 9.7 cm)
TOE_POINT = (0.105, -0.025, 0.0)  # ball of the foot in the foot box (box: x -0.044..0.134, y -0.05..0.005)
HUMANOID3D = [
    ("root", -1, (0.0, 0.0, 0.0), "root", 1),
    ("chest", 0, (0.0, 0.236151, 0.0), "quat", 8),
    ("neck", 1, (0.0, 0.223894, 0.0), "quat", 12),
    ("head", 2, HEAD_POINT, "virtual", None),
    ("right_hip", 0, (0.0, 0.0, 0.084887), "quat", 16),
    ("right_knee", 4, (0.0, -0.421546, 0.0), "knee", 20),
    ("right_ankle", 5, (0.0, -0.409870, 0.0), "quat", 21),
    ("right_toe", 6, TOE_POINT, "virtual", None),
    ("right_shoulder", 1, (-0.02405, 0.24350, 0.18311), "quat", 25),
    ("right_elbow", 8, (0.0, -0.274788, 0.0), "knee", 29),
    ("right_wrist", 9, (0.0, -0.258947, 0.0), "fixed", None),
    ("left_hip", 0, (0.0, 0.0, -0.084887), "quat", 30),
    ("left_knee", 11, (0.0, -0.421546, 0.0), "knee", 34),
    ("left_ankle", 12, (0.0, -0.409870, 0.0), "quat", 35),
    ("left_toe", 13, (TOE_POINT[0], TOE_POINT[1], -TOE_POINT[2]), "virtual", None),
    ("left_shoulder", 1, (-0.02405, 0.24350, -0.18311), "quat", 39),
    ("left_elbow", 15, (0.0, -0.274788, 0.0), "knee", 43),
    ("left_wrist", 16, (0.0, -0.258947, 0.0), "fixed", None),
]
NAMES = [j[0] for j in HUMANOID3D]
PARENTS = np.array([j[1] for j in HUMANOID3D], dtype=np.int64)
OFFSETS = np.array([j[2] for j in HUMANOID3D], dtype=np.float64)
QUAT_STARTS = [4] + [j[4] for j in HUMANOID3D if j[3] == "quat"]   # root rotation + local quaternions
ANGLE_COLUMNS = [j[4] for j in HUMANOID3D if j[3] == "knee"]
# DeepMimic (faces +X, right at +Z) -> ShapeMove (faces +Z, left at +X): x' = -z, y' = y, z' = x
TO_SHAPEMOVE = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])


def _heading(q: np.ndarray) -> float:
    """Rotation about +Y (radians) that a root quaternion (4,) gives the character's forward (+X)."""
    fwd = quaternion_to_matrix(q)[:, 0]
    return math.atan2(-fwd[2], fwd[0])


def _parse(path: Path) -> tuple[np.ndarray, str]:
    """The (N, 44) frame table and the loop mode of a DeepMimic file, validated."""
    text = read_text(path, "DeepMimic motion", MAX_BYTES)

    def no_constants(name):
        raise ValueError(f"{name} is not a number")

    try:
        data = json.loads(text, parse_constant=no_constants)
    except (ValueError, RecursionError) as exc:
        raise ShapeMoveError(f"{path}: not a DeepMimic motion (invalid JSON: {str(exc)[:120]})") from None
    if not isinstance(data, dict) or "Frames" not in data:
        raise ShapeMoveError(f"{path}: not a DeepMimic motion (no \"Frames\" list in the JSON object)")
    loop = data.get("Loop", "none")
    if not isinstance(loop, str) or loop.lower() not in ("wrap", "none"):
        raise ShapeMoveError(f"{path}: unknown \"Loop\" mode {str(loop)[:40]!r} (expected \"wrap\" or \"none\")")
    frames = data["Frames"]
    if not isinstance(frames, list) or len(frames) < 2:
        raise ShapeMoveError(f"{path}: a DeepMimic motion needs at least 2 frames in \"Frames\"")
    if len(frames) > MAX_FRAMES:
        raise ShapeMoveError(f"{path}: {len(frames)} frames is more than the limit of {MAX_FRAMES}")
    for i, row in enumerate(frames):
        if not isinstance(row, list) or len(row) != FRAME_VALUES:
            got = len(row) if isinstance(row, list) else type(row).__name__
            raise ShapeMoveError(f"{path}: frame {i} has {got} values; the humanoid3d layout has {FRAME_VALUES} "
                                 "(duration, root position 3, 8 quaternions, 4 joint angles)")
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in row):
            raise ShapeMoveError(f"{path}: frame {i} holds something that is not a number")
    table = np.asarray(frames, dtype=np.float64)
    if not np.all(np.isfinite(table)) or np.abs(table).max() > MAX_ABS:
        raise ShapeMoveError(f"{path}: values out of range (non-finite or larger than {MAX_ABS:g})")
    return table, loop.lower()


def _check(path: Path, table: np.ndarray) -> float:
    """Validate durations and quaternions in place (quaternions normalised); returns the frame time."""
    dur = table[:-1, 0]
    if np.any(dur < 0) or np.any(dur > 1.0):
        raise ShapeMoveError(f"{path}: frame durations must lie between 0 and 1 s")
    dt = float(np.median(dur))
    if not 1e-3 <= dt <= 1.0:
        raise ShapeMoveError(f"{path}: implausible frame duration {dt:g} s (expected about 1/120 to 1/10 s)")
    for c in QUAT_STARTS:
        q = table[:, c:c + 4]
        n = np.linalg.norm(q, axis=1)
        if np.any(n < 0.5) or np.any(n > 1.5):
            bad = int(np.argmax((n < 0.5) | (n > 1.5)))
            raise ShapeMoveError(f"{path}: frame {bad} has a rotation quaternion of length {n[bad]:.3g} "
                                 f"at values {c}-{c + 3} (expected a unit quaternion w, x, y, z)")
        table[:, c:c + 4] = q / n[:, None]
    return dt


def _uniform(table: np.ndarray, dt: float) -> np.ndarray:
    """Frames resampled to a constant frame time ``dt`` (positions and angles linearly, quaternions
    by slerp along the shortest arc). A no-op when the durations are already even."""
    dur = table[:-1, 0]
    if np.allclose(dur, dt, rtol=1e-3, atol=1e-6):
        return table
    times = np.concatenate([[0.0], np.cumsum(dur)])
    grid = np.arange(0.0, times[-1] + 0.5 * dt, dt)
    grid = grid[grid <= times[-1] + 1e-9]
    k = np.clip(np.searchsorted(times, grid, side="right") - 1, 0, len(times) - 2)
    span = np.maximum(times[k + 1] - times[k], 1e-12)
    w = np.clip((grid - times[k]) / span, 0.0, 1.0)[:, None]
    a, b = table[k], table[k + 1]
    out = (1 - w) * a + w * b
    for c in QUAT_STARTS:
        out[:, c:c + 4] = slerp(a[:, c:c + 4], b[:, c:c + 4], w[:, 0])
    out[:, 0] = dt
    return out


def _tile(table: np.ndarray, cycles: int) -> np.ndarray:
    """Repeat a wrap loop: the last frame of a cycle is the first of the next; each new cycle is
    turned about +Y and moved so its first frame continues from the previous cycle's end."""
    if cycles <= 1:
        return table
    first = table[0]
    parts, end = [table], table
    for _ in range(cycles - 1):
        ang = _heading(end[-1, 4:8]) - _heading(first[4:8])
        R = yaw_matrix(ang)
        nxt = table[1:].copy()
        rel = nxt[:, 1:4] - first[1:4]
        rel[:, 1] = 0.0
        nxt[:, 1:4] = rel @ R.T + np.array([end[-1, 1], 0.0, end[-1, 3]])
        nxt[:, 2] = table[1:, 2]
        nxt[:, 4:8] = matrix_to_quaternion(R @ quaternion_to_matrix(nxt[:, 4:8]))
        parts.append(nxt)
        end = nxt
    return np.concatenate(parts)


def local_rotations(table: np.ndarray) -> np.ndarray:
    """(T, J, 3, 3) local joint rotations of the HUMANOID3D joints in DeepMimic's frame."""
    T = table.shape[0]
    rot = np.broadcast_to(np.eye(3), (T, len(HUMANOID3D), 3, 3)).copy()
    for j, (_, _, _, kind, col) in enumerate(HUMANOID3D):
        if kind == "root":
            rot[:, j] = quaternion_to_matrix(table[:, 4:8])
        elif kind == "quat":
            rot[:, j] = quaternion_to_matrix(table[:, col:col + 4])
        elif kind == "knee":
            rot[:, j] = axis_rotation("z", table[:, col])
    return rot


def load_deepmimic(path, loop_min_seconds: float = LOOP_MIN_SECONDS, subject: str = "deepmimic"):
    """Read a DeepMimic motion file into a ``mocap.Mocap`` (metres, Y up, facing +Z)."""
    path = Path(path)
    if not path.is_file():
        raise ShapeMoveError(f"motion file not found: {path}")
    table, loop = _parse(path)
    n_file = table.shape[0]
    dt = _check(path, table)
    if table[:-1, 0].sum() > MAX_SECONDS:
        raise ShapeMoveError(f"{path}: the motion lasts more than {MAX_SECONDS / 60:.0f} min; split it into shorter clips")
    table = _uniform(table, dt)
    cycles = 1
    if loop == "wrap":
        period = (table.shape[0] - 1) * dt
        cycles = int(min(MAX_CYCLES, max(1, math.ceil(loop_min_seconds / max(period, 1e-9)))))
        table = _tile(table, cycles)
    check_joint_frames(table.shape[0], len(HUMANOID3D), path)
    rot = local_rotations(table)
    offsets = np.broadcast_to(OFFSETS, (table.shape[0], len(HUMANOID3D), 3)).copy()
    offsets[:, 0] = table[:, 1:4]  # the root's rest position is its position in each frame
    positions, _ = forward_kinematics(rot, joints_from_offsets(offsets, PARENTS), PARENTS)
    C = TO_SHAPEMOVE
    positions = positions @ C.T
    rotations = C @ rot @ C.T
    offsets = OFFSETS @ C.T
    offsets[0] = positions[0, 0]
    meta = {"loop": loop, "cycles": cycles, "frames_in_file": n_file, "frame_time": dt}
    return finish_mocap(NAMES, PARENTS, offsets, positions, 1.0 / dt, str(path), rotations=rotations,
                        unit="m", scale=1.0, up_axis="Y", subject=subject, meta=meta)

