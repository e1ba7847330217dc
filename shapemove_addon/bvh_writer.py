"""Write an armature's evaluated animation as a Y-up BVH in centimetres.

Blender's own BVH exporter writes the armature's axes as they are (Z-up here) and the bone rest
frames into the rotations, so its importer (default: Y-up files) lays the rig on its back. This
writer reads the evaluated pose of every frame and writes what other tools expect:
- Y up, the body facing +Z, lengths in centimetres (``UNIT_SCALE``);
- every joint's rest frame aligned with the world (the usual BVH rest pose), so a channel value
  is the joint's rotation relative to its parent in the world axes; Euler order Z, X, Y
  (``CHANNELS ... Zrotation Xrotation Yrotation``, i.e. R = Rz @ Rx @ Ry);
- the root's position channels hold its absolute position (they replace its OFFSET, as in
  Blender's importer and ``core.io.bvh``).
Frame k of the file is scene frame ``start + k``; Frame Time is 1 / the scene's frame rate.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from mathutils import Euler, Matrix

from ..core.scene.axes import Y_UP_TO_Z_UP, points_to_y_up

UNIT_SCALE = 100.0  # metres -> centimetres


def _order(arm_obj) -> list:
    """Bones depth-first from each root, children in the armature's order (BVH nesting order)."""
    out = []

    def visit(bone):
        out.append(bone)
        for child in bone.children:
            visit(child)
    for bone in arm_obj.data.bones:
        if bone.parent is None:
            visit(bone)
    return out


def _rotation(m) -> np.ndarray:
    """The rotation of a 4x4 (scale removed), as a 3x3 float64 array."""
    r = np.array(m, dtype=np.float64)[:3, :3]
    u, _, vt = np.linalg.svd(r)
    return u @ vt


def write_bvh(scene, arm_obj, path, frame_start: int, frame_end: int) -> Path:
    """Evaluate ``arm_obj`` at every scene frame of [frame_start, frame_end] and write ``path``
    (as it is: ``export.export_rig`` gives a temporary name and renames it when complete)."""
    bones = _order(arm_obj)
    index = {b.name: i for i, b in enumerate(bones)}
    parents = [index[b.parent.name] if b.parent else -1 for b in bones]
    world = np.array(arm_obj.matrix_world, dtype=np.float64)
    rest = np.array([np.array(b.matrix_local, dtype=np.float64) for b in bones])  # armature space
    rest_heads = points_to_y_up(rest[:, :3, 3] @ world[:3, :3].T + world[:3, 3])
    tails = points_to_y_up(np.array([list(b.tail_local) for b in bones]) @ world[:3, :3].T + world[:3, 3])
    rest_rot = np.array([_rotation(world @ r) for r in rest])

    lines = ["HIERARCHY"]

    def node(i, depth):
        pad = "\t" * depth
        p = parents[i]
        offset = (rest_heads[i] - (rest_heads[p] if p >= 0 else 0.0)) * UNIT_SCALE
        lines.append(f"{pad}{'ROOT' if p < 0 else 'JOINT'} {bones[i].name}")
        lines.append(pad + "{")
        lines.append(f"{pad}\tOFFSET {offset[0]:.6f} {offset[1]:.6f} {offset[2]:.6f}")
        if p < 0:
            lines.append(f"{pad}\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation")
        else:
            lines.append(f"{pad}\tCHANNELS 3 Zrotation Xrotation Yrotation")
        kids = [index[c.name] for c in bones[i].children]
        for k in kids:
            node(k, depth + 1)
        if not kids:
            end = (tails[i] - rest_heads[i]) * UNIT_SCALE
            lines.extend([f"{pad}\tEnd Site", pad + "\t{", f"{pad}\t\tOFFSET {end[0]:.6f} {end[1]:.6f} {end[2]:.6f}",
                          pad + "\t}"])
        lines.append(pad + "}")

    for i, p in enumerate(parents):
        if p < 0:
            node(i, 0)

    fps = scene.render.fps / scene.render.fps_base
    frames = list(range(int(frame_start), int(frame_end) + 1))
    lines += ["MOTION", f"Frames: {len(frames)}", f"Frame Time: {1.0 / fps:.8f}"]
    current = scene.frame_current
    prev = [Euler((0.0, 0.0, 0.0), "YXZ") for _ in bones]
    try:
        for f in frames:
            scene.frame_set(f)
            world = np.array(arm_obj.matrix_world, dtype=np.float64)
            posed = [world @ np.array(arm_obj.pose.bones[b.name].matrix, dtype=np.float64) for b in bones]
            # world rotation taking each rest bone to its posed frame, in Y-up axes
            g = Y_UP_TO_Z_UP.T @ np.array([_rotation(m) @ r.T for m, r in zip(posed, rest_rot)]) @ Y_UP_TO_Z_UP
            row = []
            for i, p in enumerate(parents):
                local = g[i] if p < 0 else g[p].T @ g[i]
                # Blender's "YXZ" Euler is R = Rz @ Rx @ Ry: the channels Z, X, Y in file order
                e = Matrix(local.tolist()).to_euler("YXZ", prev[i])
                prev[i] = e
                if p < 0:
                    row += list(points_to_y_up(posed[i][:3, 3]) * UNIT_SCALE)
                row += [math.degrees(e.z), math.degrees(e.x), math.degrees(e.y)]
            lines.append(" ".join(f"{v:.6f}" for v in row))
    finally:
        scene.frame_set(current)
    path = Path(path)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")  # the caller writes a temporary name
    return path
