"""Reading a Blender scene back as numbers, for the tests that compare it with the core maths
(imported by the bpy tests in tests/ and, through sys.path, by those in tests/in_blender/)."""
from __future__ import annotations

import bpy
import numpy as np


def bone_heads_world(arm, names) -> np.ndarray:
    """(N,3) world positions of the pose bones ``names`` of the armature object ``arm``."""
    return np.array([list(arm.matrix_world @ arm.pose.bones[n].head) for n in names])


def evaluated_vertices(obj) -> np.ndarray:
    """(V,3) world positions of the evaluated (deformed) mesh of ``obj`` at the current frame."""
    ev = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    co = np.empty(len(ev.data.vertices) * 3, dtype=np.float32)
    ev.data.vertices.foreach_get("co", co)
    m = np.array(obj.matrix_world)
    return co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
