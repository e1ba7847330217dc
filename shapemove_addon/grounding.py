"""Keep a rig's feet on the floor when its shape changes, measured on the mesh.

After the bones move to the new body, the keyed motion (the same local rotations) is grounded on
the new body's mesh the way core grounds the motions it decodes, with ``core.body.plant.
ground_shift``: on frames where a foot is in contact its lowest sole point goes to the floor
(armature z = 0), between contacts the shift is interpolated (a jump keeps its flight), without
any contact one shift for the whole clip, and no probed point ends under the floor. Whether or
not the rig's motion has tokens, this runs at once; a motion with tokens is re-decoded later.

- Contacts: detected once from the keyed motion on the body it was keyed for
  (``core.motion.contacts.detect_contacts``), cached on the rig for that action and length.
- Probe: each foot's sole vertices (``core.body.sole_height.sole_vertices``) and every
  ``BODY_STRIDE``-th other vertex, with their shape-key rows and skin weights, cached on the rig,
  so an update skins a few hundred vertices (``sole_height.lowest_heights``), not the mesh.
Armature space (Z up) throughout; the rig object is assumed unrotated, as ShapeMove builds it.
"""
from __future__ import annotations

import numpy as np

from ..core.body import sole_height
from ..core.body.plant import ground_shift
from ..core.constants import FPS, NUM_BETAS
from ..core.geometry.fk import forward_kinematics
from ..core.geometry.rotations import quaternion_to_matrix
from ..core.motion.contacts import detect_contacts
from ..core.scene.axes import points_to_y_up
from .rig_state import body_of

UP = 2  # Blender's Z
BODY_STRIDE = 48  # every n-th vertex outside the soles is probed (knees, hands, seat on the floor)
LEFT, RIGHT, BODY = 0, 1, 2
PROBE = "shapemove_probe"  # custom-property prefix of the cached probe
CONTACTS, CONTACTS_FOR = "shapemove_contacts", "shapemove_contacts_for"
GROUND_REF, GROUND_LAST = "shapemove_ground_ref", "shapemove_ground_last"  # root heights: run start, last written


def _read_key(key_block, count: int) -> np.ndarray:
    co = np.empty(3 * count, dtype=np.float32)
    key_block.data.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64)


def _probe(rig, names):
    """(basis (n,3), dirs (n,3,10), weights (n,J), groups (n,)) of the probed vertices, or None
    when the body has no beta shape keys. Cached on ``rig`` while the mesh keeps its size."""
    body = body_of(rig)
    if body is None or body.data.shape_keys is None:
        return None
    count, n_joints = len(body.data.vertices), len(names)
    if rig.get(PROBE + "_vertex_count") == count and len(rig.get(PROBE + "_weights", [])) == n_joints * len(
            rig.get(PROBE + "_groups", [])) > 0:
        n = len(rig[PROBE + "_groups"])
        return (np.array(rig[PROBE + "_basis"], dtype=np.float64).reshape(n, 3),  # copies, not views
                np.array(rig[PROBE + "_dirs"], dtype=np.float64).reshape(n, 3, NUM_BETAS),
                np.array(rig[PROBE + "_weights"], dtype=np.float64).reshape(n, n_joints),
                np.array(rig[PROBE + "_groups"], dtype=np.int64))
    keys = body.data.shape_keys.key_blocks
    if any(f"beta_{i}" not in keys for i in range(NUM_BETAS)):
        return None
    basis = _read_key(keys[0], count)
    dirs = np.stack([_read_key(keys[f"beta_{i}"], count) - basis for i in range(NUM_BETAS)], -1)  # (V,3,10)
    rest = basis + dirs @ np.array([keys[f"beta_{i}"].value for i in range(NUM_BETAS)])
    band = rest[:, UP] <= rest[:, UP].min() + sole_height.SOLE_BAND
    sample = np.flatnonzero(~band)[::BODY_STRIDE]
    # skin weights of the band and the sample only (reading every vertex's groups would take long)
    joint_of_group = {g.index: names.index(g.name) for g in body.vertex_groups if g.name in names}
    weights = np.zeros((count, n_joints))
    verts = body.data.vertices
    for i in np.r_[np.flatnonzero(band), sample]:
        for g in verts[int(i)].groups:
            j = joint_of_group.get(g.group)
            if j is not None:
                weights[i, j] = g.weight
    soles = sole_height.sole_vertices(rest, weights, UP)
    side = np.array([LEFT if n.startswith("left") else RIGHT if n.startswith("right") else BODY for n in names])
    ids = np.r_[soles, sample]
    groups = np.r_[side[weights[soles].argmax(1)], np.full(len(sample), BODY)]
    rig[PROBE + "_basis"] = basis[ids].ravel().tolist()
    rig[PROBE + "_dirs"] = dirs[ids].ravel().tolist()
    rig[PROBE + "_weights"] = weights[ids].ravel().tolist()
    rig[PROBE + "_groups"] = groups.tolist()
    rig[PROBE + "_vertex_count"] = count
    return basis[ids], dirs[ids], weights[ids], groups


def _skeleton(rig, betas):
    """(rest joints (...,J,3) for betas (...,10), parents)."""
    jt = np.array(rig["shapemove_joint_template"], dtype=np.float64).reshape(-1, 3)
    jd = np.array(rig["shapemove_joint_shapedirs"], dtype=np.float64).reshape(len(jt), 3, NUM_BETAS)
    return jt + np.einsum("jkb,...b->...jk", jd, np.asarray(betas, dtype=np.float64)), [int(p) for p in rig["shapemove_parents"]]


def lowest(rig, names, betas, rotations, offsets):
    """(...,T,3) lowest point of the left sole, the right sole and the probed body of ``rig``'s
    body with betas (...,10), posed by local rotations (T,J,3,3, armature axes) and root offsets
    (T,3); None without shape keys."""
    probe = _probe(rig, names)
    if probe is None:
        return None
    basis, dirs, weights, groups = probe
    joints, parents = _skeleton(rig, betas)
    verts = basis + np.einsum("nkb,...b->...nk", dirs, np.asarray(betas, dtype=np.float64))
    return sole_height.lowest_heights(rotations, offsets, joints, parents, verts, weights, UP, groups)


def contacts(rig, betas, rotations, offsets):
    """(T,4) foot contacts of the rig's keyed motion (joints 7, 8, 10, 11), detected on the body
    with ``betas`` the first time and cached for the rig's action and length."""
    anim = rig.animation_data
    tag = f"{anim.action.name if anim and anim.action else ''}:{len(rotations)}"
    if rig.get(CONTACTS_FOR) == tag and len(rig.get(CONTACTS, [])) == 4 * len(rotations):
        return np.array(rig[CONTACTS], dtype=np.uint8).reshape(-1, 4)
    joints, parents = _skeleton(rig, betas)
    posed, _ = forward_kinematics(rotations, joints, parents)
    fps = float(anim.action.get("shapemove_fps", FPS)) if anim and anim.action else FPS
    found = detect_contacts(points_to_y_up(posed[:, :22] + np.asarray(offsets)[:, None]), fps)
    rig[CONTACTS] = found.ravel().tolist()
    rig[CONTACTS_FOR] = tag
    return found


def forget_contacts(rig) -> None:
    """The rig's action was replaced: detect its contacts again at the next shape change."""
    for key in (CONTACTS, CONTACTS_FOR, GROUND_REF, GROUND_LAST):
        if key in rig:
            del rig[key]


def keyed_pose(quats, locations, rest_frames):
    """Pose-bone keys -> (local rotations (T,J,3,3), root offsets (T,3)) in armature axes.
    quats (J,T,4) against the bones' rest frames rest_frames (J,3,3); locations (T,3) root keys."""
    q = quaternion_to_matrix(np.asarray(quats, dtype=np.float64))  # (J,T,3,3)
    b = np.asarray(rest_frames, dtype=np.float64)[:, None]
    rot = np.swapaxes(b @ q @ np.swapaxes(b, -1, -2), 0, 1)
    return rot, np.asarray(locations, dtype=np.float64) @ np.asarray(rest_frames[0], dtype=np.float64).T


def ground_keys(rig, names, old_betas, new_betas, keys) -> bool:
    """Ground the rebased keys (``bone_placement.RebasedKeys``) on the new body's mesh: move the
    root's location keys up or down per frame (``plant.ground_shift`` with the motion's contacts).

    The shift is computed from the root heights the motion had before the first of a run of shape
    changes (kept on the rig with the heights last written; a motion edited meanwhile starts a new
    run), not from the last result, so the clamps of the grounding cannot pile up: going back to
    the first betas gives the first keys back. False when the rig has no shape keys."""
    rotations, offsets = keyed_pose(keys.quats, keys.locations, keys.rest)
    z = offsets[:, UP]
    last, ref = rig.get(GROUND_LAST), rig.get(GROUND_REF)
    if last is not None and ref is not None and len(last) == len(z) == len(ref) and \
            np.abs(np.array(last, dtype=np.float64) - z).max() < 1e-6:
        ref = np.array(ref, dtype=np.float64)
    else:
        ref = z.copy()
    base = offsets.copy()
    base[:, UP] = ref
    low = lowest(rig, names, new_betas, rotations, base)
    if low is None:
        return False
    target = ref + ground_shift(low[:, :2], low.min(-1), contacts(rig, old_betas, rotations, offsets))
    keys.set_locations(keys.locations + (target - z)[:, None] * np.asarray(keys.rest[0])[UP])  # armature Z in the root's frame
    rig[GROUND_REF] = ref.tolist()
    rig[GROUND_LAST] = target.tolist()
    return True
