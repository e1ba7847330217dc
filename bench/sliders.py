"""Shape-slider updates on the default body: time per update and drift.

Builds an OpenBody rig (bpy module) for a 6 s motion (120 frames at 20 fps), then moves one beta
slider at a time through ``shape_sync.set_betas`` (what the panel's sliders call): bones re-placed,
keys rebased, feet re-grounded on the mesh soles, scene re-evaluated. (The first update grounds the
random test motion on the mesh and is not counted.) Reports the median wall time
and CPU time of an update (the goal is <= 30 ms) and, after 200 moves and a return to the first
shape, how far the bones moved (the goal is <= 0.05 mm).
"""
from __future__ import annotations

import time

import numpy as np

from ..core.scene.bodies import load_body
from ..core.scene.motion_file import make_motion


def run(quick: bool = False) -> dict:
    import bpy

    from ..shapemove_addon.scene_build import build_rig
    from ..shapemove_addon.shape_sync import set_betas

    frames, moves = (60, 40) if quick else (120, 200)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    body = load_body("openbody-v1")
    rng = np.random.default_rng(0)
    t = np.arange(frames)[:, None, None]
    poses = rng.normal(0, 0.3, (1, 24, 3)) * np.sin(0.2 * t + rng.uniform(0, 6, (1, 24, 3)))
    transl = np.stack([0.01 * np.arange(frames), np.zeros(frames), 0.04 * np.arange(frames)], -1)
    betas = rng.normal(0, 0.7, 10)
    rig = build_rig(bpy.context, make_motion(body, poses, transl, betas), body, name="Bench").armature
    bpy.context.view_layer.objects.active = rig
    names = rig["shapemove_joint_names"].split("\n")

    def heads():
        out = []
        for f in range(1, frames + 1, max(1, frames // 8)):
            bpy.context.scene.frame_set(f)
            out.append([list(rig.matrix_world @ rig.pose.bones[n].head) for n in names])
        return np.array(out)

    set_betas(rig, betas)  # the first update grounds the motion on the mesh and caches the probe: not timed
    before = heads()
    wall, cpu = [], []
    moved = betas.copy()
    for k in range(moves):
        moved[k % 10] = betas[k % 10] + rng.uniform(-2, 2)
        t0, c0 = time.perf_counter(), time.process_time()
        set_betas(rig, moved)
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    set_betas(rig, betas)
    drift = float(np.abs(heads() - before).max())
    out = {"slider_update_ms": 1e3 * float(np.median(wall)), "slider_update_cpu_ms": 1e3 * float(np.median(cpu)),
           "slider_update_p90_ms": 1e3 * float(np.percentile(wall, 90)), "slider_drift_mm": 1e3 * drift}
    print(f"slider update on OpenBody, {frames} frames: median {out['slider_update_ms']:.1f} ms wall, "
          f"{out['slider_update_cpu_ms']:.1f} ms CPU, p90 {out['slider_update_p90_ms']:.1f} ms (goal <= 30 ms)")
    print(f"drift after {moves} slider moves and back: {out['slider_drift_mm']:.4f} mm (goal <= 0.05 mm)")
    return out
