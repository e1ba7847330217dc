"""Detect a T-pose lead-in at the start of a clip (mocap calibration pose, or the rest frame that
BVH converters put first) so it can be cut.

Works on SMPL22 positions (T,22,3), metres, Y up. A frame is a T-pose when both arms are straight,
horizontal (within 25 deg) and point sideways. A leading run of such frames is cut when it is
held (joints moving < 0.5 m/s); a single rest frame followed by a jump (what BVH converters write)
is cut too; so are the blend frames that follow either (joint speeds far above the clip's own,
at most 0.25 s of them).
"""
from __future__ import annotations

import numpy as np

ARM_ELEVATION_DEG = 25.0
STRAIGHT = 0.9      # |wrist - shoulder| / (upper arm + forearm)
SIDEWAYS_COS = np.cos(np.radians(35.0))
STATIC_SPEED = 0.5  # m/s


def is_tpose(joints: np.ndarray) -> np.ndarray:
    """(T,22,3) -> (T,) bool: arms straight, horizontal and sideways."""
    across = joints[:, 16] - joints[:, 17]  # right shoulder -> left shoulder
    across[:, 1] = 0
    across /= np.maximum(np.linalg.norm(across, axis=-1, keepdims=True), 1e-9)
    ok = np.ones(len(joints), bool)
    for sh, el, wr, sign in ((16, 18, 20, 1.0), (17, 19, 21, -1.0)):
        arm = joints[:, wr] - joints[:, sh]
        n = np.maximum(np.linalg.norm(arm, axis=-1), 1e-9)
        reach = (np.linalg.norm(joints[:, el] - joints[:, sh], axis=-1)
                 + np.linalg.norm(joints[:, wr] - joints[:, el], axis=-1))
        elev = np.degrees(np.arcsin(np.clip(arm[:, 1] / n, -1, 1)))
        side = sign * np.sum(arm * across, -1) / n
        ok &= (np.abs(elev) < ARM_ELEVATION_DEG) & (n > STRAIGHT * reach) & (side > SIDEWAYS_COS)
    return ok


def tpose_lead_in(joints: np.ndarray, fps: float) -> int:
    """Number of leading frames to drop (0 when the clip does not start in a T-pose)."""
    T = len(joints)
    if T < 3:
        return 0
    tp = is_tpose(joints)
    run = int(np.argmin(tp)) if not tp.all() else T
    if run == 0:
        return 0
    speed = np.linalg.norm(np.diff(joints, axis=0), axis=-1).max(-1) * fps  # speed[k]: frame k -> k+1
    threshold = max(5.0, 2.0 * float(np.median(speed)))
    jump = speed[0] > threshold  # a converter's rest frame, then a jump into the motion
    held = lambda a, b: b - a > 1 and np.median(speed[a: b - 1]) < STATIC_SPEED  # noqa: E731
    if not (jump or held(0, run)):
        return 0  # arms out while moving: part of the motion
    cut = 1 if jump else run

    def skip_blend(k):  # frames far faster than the clip are the converter's blend out of the T-pose
        limit = min(T - 1, k + int(round(0.25 * fps)))
        while k < limit and speed[k] > threshold:
            k += 1
        return k

    cut = skip_blend(cut)
    if cut < run and held(cut, run):  # a held T-pose after the rest frame
        cut = skip_blend(run)
    return min(cut, T)
