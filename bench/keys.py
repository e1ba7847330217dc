"""Keyframe writer vs a ``keyframe_insert`` loop, same motion, same run.

Builds a capsule-body rig (bpy module), then keys a T-frame motion on its 24 bones twice: with
``write_pose_action`` (F-Curves filled by ``foreach_set``) and with the usual per-frame, per-bone
``keyframe_insert`` loop (quaternions precomputed, so only key writing is timed). Both results
are compared key by key before the ratio is reported.
"""
from __future__ import annotations

import time

import numpy as np

from ..core.scene.motion_file import make_motion
from ..core.scene.pose import pose_bone_quaternions, root_locations
from ..core.scene.rig_data import motion_channels_z_up


def _motion(body, frames: int):
    rng = np.random.default_rng(0)
    t = np.arange(frames)[:, None, None]
    poses = rng.normal(0, 0.4, (1, 24, 3)) * np.sin(0.15 * t + rng.uniform(0, 6, (1, 24, 3)))
    transl = np.stack([0.01 * np.arange(frames), np.zeros(frames), 0.03 * np.arange(frames)], -1)
    return make_motion(body, poses, transl, np.zeros(10))


def _keys(action, obj):
    from ..shapemove_addon.keyframes import action_fcurves

    out = {}
    for fc in action_fcurves(action, obj):
        co = np.empty(2 * len(fc.keyframe_points), dtype=np.float32)
        fc.keyframe_points.foreach_get("co", co)
        out[(fc.data_path, fc.array_index)] = co.reshape(-1, 2)
    return out


def run(quick: bool = False) -> dict:
    import bpy

    from ..core.scene.capsule_body import capsule_body
    from ..shapemove_addon.bone_placement import rest_rotations
    from ..shapemove_addon.keyframes import FIRST_FRAME, write_pose_action
    from ..shapemove_addon.scene_build import build_rig

    frames = 60 if quick else 400
    bpy.ops.wm.read_factory_settings(use_empty=True)
    body = capsule_body()
    motion = _motion(body, frames)
    arm = build_rig(bpy.context, motion, body, name="Bench").armature
    names = arm["shapemove_joint_names"].split("\n")
    rot, transl = motion_channels_z_up(motion.poses, motion.transl)

    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        action = write_pose_action(arm, rot, transl, motion.fps, names, "bench_writer")
        best = min(best, time.perf_counter() - t0)
    fast = _keys(action, arm)

    rest = rest_rotations(arm, names)
    quats = pose_bone_quaternions(rot, rest)
    locs = root_locations(transl, rest[0])
    arm.animation_data.action = None
    pbones = [arm.pose.bones[n] for n in names]
    t0 = time.perf_counter()
    for t in range(frames):
        f = FIRST_FRAME + t
        for j, pb in enumerate(pbones):
            pb.rotation_quaternion = quats[t, j]
            pb.keyframe_insert("rotation_quaternion", frame=f, group=pb.name)
        pbones[0].location = locs[t]
        pbones[0].keyframe_insert("location", frame=f, group=pbones[0].name)
    slow_time = time.perf_counter() - t0
    slow = _keys(arm.animation_data.action, arm)

    if fast.keys() != slow.keys():
        raise RuntimeError("the two methods keyed different channels")
    worst = max(float(np.abs(fast[k] - slow[k]).max()) for k in fast)
    if worst > 1e-5:
        raise RuntimeError(f"the two methods keyed different values (max difference {worst:g})")
    ratio = slow_time / best
    print(f"keyframe_insert loop: {slow_time * 1e3:.1f} ms for {frames} frames x {len(names)} bones (baseline)")
    print(f"write_pose_action:   {best * 1e3:.1f} ms  (same keys, max |difference| {worst:.1e})")
    print(f"keys_speedup: {ratio:.1f}x")
    return {"keys_speedup": ratio}
