"""Keep a rig's feet on the floor when its shape changes, measured on the mesh soles.

The sole vertices of the body (``core.scene.sole_height``) are picked once per rig, with their
shape-key rows and skin weights, and cached on the armature as custom properties, so each slider
move skins only those few vertices for the keyed motion, for the old and the new betas.
``shape_change_shift`` gives the per-frame root shift (armature Z) that keeps every frame's
lowest sole point where it was; ``floor_shift`` the constant one that puts a newly keyed motion
on the floor (z = 0). The Z-up armature space of the rig is used throughout.
"""
from __future__ import annotations

import numpy as np

from ..core.constants import NUM_BETAS
from ..core.geometry.rotations import quaternion_to_matrix
from ..core.scene import sole_height
from .rig_state import body_of

UP = 2  # Blender's Z
IDS_KEY, BASIS_KEY, DIRS_KEY, WEIGHTS_KEY, COUNT_KEY = (
    "shapemove_sole_ids", "shapemove_sole_basis", "shapemove_sole_dirs", "shapemove_sole_weights",
    "shapemove_sole_vertex_count")


def _read_key(key_block, count: int) -> np.ndarray:
    co = np.empty(3 * count, dtype=np.float32)
    key_block.data.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64)


def _sole_arrays(rig, names):
    """(basis (n,3), dirs (n,3,10), weights (n,J)) of the rig's sole vertices, or None when the
    body has no beta shape keys. Cached on ``rig`` while the mesh keeps its vertex count."""
    body = body_of(rig)
    if body is None or body.data.shape_keys is None:
        return None
    count = len(body.data.vertices)
    n_joints = len(names)
    if rig.get(COUNT_KEY) == count and len(rig.get(WEIGHTS_KEY, [])) == n_joints * len(rig.get(IDS_KEY, [])) > 0:
        n = len(rig[IDS_KEY])
        return (np.array(rig[BASIS_KEY], dtype=np.float64).reshape(n, 3),
                np.array(rig[DIRS_KEY], dtype=np.float64).reshape(n, 3, NUM_BETAS),
                np.array(rig[WEIGHTS_KEY], dtype=np.float64).reshape(n, n_joints))
    keys = body.data.shape_keys.key_blocks
    if any(f"beta_{i}" not in keys for i in range(NUM_BETAS)):
        return None
    basis = _read_key(keys[0], count)
    dirs = np.stack([_read_key(keys[f"beta_{i}"], count) - basis for i in range(NUM_BETAS)], -1)  # (V,3,10)
    rest = basis + dirs @ np.array([keys[f"beta_{i}"].value for i in range(NUM_BETAS)])
    # skin weights of the sole band only (reading every vertex's groups would take long)
    band = np.flatnonzero(rest[:, UP] <= rest[:, UP].min() + sole_height.SOLE_BAND)
    joint_of_group = {g.index: names.index(g.name) for g in body.vertex_groups if g.name in names}
    all_weights = np.zeros((count, n_joints))
    verts = body.data.vertices
    for i in band:
        for g in verts[int(i)].groups:
            j = joint_of_group.get(g.group)
            if j is not None:
                all_weights[i, j] = g.weight
    ids = sole_height.sole_vertices(rest, all_weights, UP)
    weights = all_weights[ids]
    rig[IDS_KEY] = ids.tolist()
    rig[BASIS_KEY] = basis[ids].ravel().tolist()
    rig[DIRS_KEY] = dirs[ids].ravel().tolist()
    rig[WEIGHTS_KEY] = weights.ravel().tolist()
    rig[COUNT_KEY] = count
    return basis[ids], dirs[ids], weights


def _rig_skeleton(rig):
    jt = np.array(rig["shapemove_joint_template"], dtype=np.float64).reshape(-1, 3)
    jd = np.array(rig["shapemove_joint_shapedirs"], dtype=np.float64).reshape(len(jt), 3, NUM_BETAS)
    return jt, jd, [int(p) for p in rig["shapemove_parents"]]


def lowest_soles(rig, names, betas, rotations, offsets):
    """(...,T) lowest sole height (armature Z) of ``rig``'s body for betas (...,10) posed by local
    joint rotations (T,J,3,3, armature axes) and root offsets (T,3); None without sole data."""
    soles = _sole_arrays(rig, names)
    if soles is None:
        return None
    basis, dirs, weights = soles
    jt, jd, parents = _rig_skeleton(rig)
    betas = np.asarray(betas, dtype=np.float64)
    joints = jt + np.einsum("jkb,...b->...jk", jd, betas)
    verts = basis + np.einsum("nkb,...b->...nk", dirs, betas)
    return sole_height.lowest_sole_heights(rotations, offsets, joints, parents, verts, weights, UP)


def keyed_pose(quats, locations, rest_frames):
    """Pose-bone keys -> (local rotations (T,J,3,3), root offsets (T,3)) in armature axes.
    quats (J,T,4) against the bones' rest frames rest_frames (J,3,3); locations (T,3) root keys."""
    q = quaternion_to_matrix(np.asarray(quats, dtype=np.float64))  # (J,T,3,3)
    b = np.asarray(rest_frames, dtype=np.float64)[:, None]
    rot = np.swapaxes(b @ q @ np.swapaxes(b, -1, -2), 0, 1)
    return rot, np.asarray(locations, dtype=np.float64) @ np.asarray(rest_frames[0], dtype=np.float64).T


def shape_change_shift(rig, names, old_betas, new_betas, rotations, offsets):
    """(T,) armature-Z root shift keeping every frame's lowest sole point where it was, or None."""
    both = lowest_soles(rig, names, np.stack([old_betas, new_betas]), rotations, offsets)
    return None if both is None else sole_height.shape_change_shift(both[0], both[1])


def floor_shift(rig, names, betas, rotations, offsets):
    """Constant armature-Z root shift putting the motion's lowest sole point on the floor, or 0."""
    low = lowest_soles(rig, names, betas, rotations, offsets)
    return 0.0 if low is None else sole_height.floor_shift(low)
