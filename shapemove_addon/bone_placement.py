"""Create or move the 24 bones of a ShapeMove armature so they sit on the body's rest joints.

Edit bones exist only in Edit Mode, so the armature is switched to Edit Mode for the change and
back afterwards (the previous mode and active object are restored). When bones move, the pose
keys of the rig's action are re-expressed against the new bone rest frames, so the local joint
rotations of the motion stay exactly what they were.
"""
from __future__ import annotations

import contextlib
from dataclasses import dataclass

import bpy
import numpy as np

from ..core.errors import ShapeMoveError
from ..core.scene.bones import bone_layout
from ..core.scene.pose import rebase_locations, rebase_quaternions
from .keyframes import action_fcurves


def _mode_set(mode: str) -> None:
    """``bpy.ops.object.mode_set`` without the two depsgraph evaluations that the Python wrapper
    of every operator runs (the scene is evaluated once, after all bones moved: a shape change
    then costs one evaluation of the body instead of five). Falls back to the wrapper when the
    internal call is not available."""
    try:
        from _bpy import ops as _ops
        call = _ops.call
    except (ImportError, AttributeError):
        bpy.ops.object.mode_set(mode=mode)
        return
    if "FINISHED" not in call("object.mode_set", {"mode": mode}):
        raise RuntimeError(f"could not switch to {mode} mode")


@contextlib.contextmanager
def edit_bones_of(context, arm_obj):
    """Yield ``arm_obj.data.edit_bones`` with the armature in Edit Mode; restore mode and active."""
    if context.mode not in ("OBJECT", "POSE", "EDIT_ARMATURE"):
        raise ShapeMoveError("switch to Object Mode or Pose Mode first")
    view_layer = context.view_layer
    if view_layer.objects.get(arm_obj.name) is None:
        raise ShapeMoveError(f"armature {arm_obj.name!r} is not in the current view layer")
    prev_active = view_layer.objects.active
    prev_mode = arm_obj.mode
    override = dict(active_object=arm_obj, object=arm_obj, selected_objects=[arm_obj],
                    selected_editable_objects=[arm_obj], edit_object=arm_obj)
    view_layer.objects.active = arm_obj
    try:
        with context.temp_override(**override):
            if arm_obj.mode != "EDIT":
                try:
                    _mode_set("EDIT")
                except RuntimeError as exc:  # hidden, linked from a library, ...
                    raise ShapeMoveError(f"cannot edit the bones of {arm_obj.name!r}: {exc}".strip()) from None
        yield arm_obj.data.edit_bones
    finally:
        with context.temp_override(**override):
            if arm_obj.mode != prev_mode:
                _mode_set(prev_mode)
        if prev_active is not None and view_layer.objects.get(prev_active.name) is not None:
            view_layer.objects.active = prev_active


REST_FRAMES_KEY = "shapemove_rest_frames"  # float64 rest frames the keys are relative to


def _orthonormal(m) -> np.ndarray:
    """(..., 3, 3) nearest rotation (polar factor) in float64: Blender's float32 matrices are not
    quite orthonormal, and rebasing through them drifts a little with every shape change."""
    u, _, vt = np.linalg.svd(np.asarray(m, dtype=np.float64))
    r = u @ vt
    return np.where(np.linalg.det(r)[..., None, None] < 0, u @ (np.diag([1.0, 1.0, -1.0]) @ vt), r)


def rest_rotations(arm_obj, names) -> np.ndarray:
    """(J,3,3) rotation part of each bone's ``matrix_local`` (armature space rest frame), made
    orthonormal in float64."""
    m = np.empty((len(names), 16), dtype=np.float32)
    for j, n in enumerate(names):
        m[j] = np.array(arm_obj.data.bones[n].matrix_local, dtype=np.float32).ravel()
    return _orthonormal(m.reshape(-1, 4, 4)[:, :3, :3])


def _stored_rest(arm_obj, names):
    """The rest frames stored at the last placement (float64), if they are still the bones'."""
    stored = arm_obj.get(REST_FRAMES_KEY)
    if stored is None or len(stored) != 9 * len(names):
        return None
    stored = np.array(stored, dtype=np.float64).reshape(-1, 3, 3)  # a copy: asarray would view the ID property
    # the bones may have been edited by hand since: then their current frames are the truth
    return stored if np.abs(stored - rest_rotations(arm_obj, names)).max() < 1e-5 else None


@dataclass
class RebasedKeys:
    """The keys ``place_bones`` rebased: quats (J,T,4) for every bone, locations (T,3) of the root,
    against ``rest`` (J,3,3) float64 frames; ``set_locations`` rewrites the root's location keys."""
    quats: np.ndarray
    locations: np.ndarray
    rest: np.ndarray
    _location_curves: tuple

    def set_locations(self, values) -> None:
        fcs, co = self._location_curves
        _write_curves(fcs, co, np.asarray(values, dtype=np.float64))
        self.locations = np.asarray(values, dtype=np.float64)


def place_bones(context, arm_obj, rest_joints, names, parents) -> RebasedKeys | None:
    """Put bone ``names[j]`` on ``rest_joints[j]`` (J,3, armature space, Z-up), creating the
    bones on first use; keyed rotations are rebased so the motion is unchanged. Returns the
    rebased keys when every bone and the root location are keyed on the same frames, else None.

    The keys are rebased from the float64 orthonormal rest frames stored at the previous placement
    to the new ones (stored in turn), so a series of shape changes composes exactly
    (new_k^T old_(k-1) ... telescopes) and the keyed motion does not drift."""
    layout = bone_layout(rest_joints, parents)
    existing = all(n in arm_obj.data.bones for n in names)
    old = (_stored_rest(arm_obj, names) if existing else None)
    if existing and old is None:
        old = rest_rotations(arm_obj, names)
    with edit_bones_of(context, arm_obj) as ebones:
        for j, n in enumerate(names):
            eb = ebones.get(n) or ebones.new(n)
            eb.head = layout.heads[j].tolist()
            eb.tail = layout.tails[j].tolist()
            eb.roll = float(layout.rolls[j])
            eb.use_connect = False
            eb.use_deform = True
        for j, n in enumerate(names):
            ebones[n].parent = ebones[names[parents[j]]] if parents[j] >= 0 else None
    new = rest_rotations(arm_obj, names)
    arm_obj[REST_FRAMES_KEY] = new.ravel().tolist()
    return _rebase_action(arm_obj, names, old, new) if old is not None else None


def _write_curves(fcs, co, values) -> None:
    """values (T, len(fcs)) -> the F-Curves' key values (frames kept)."""
    co[:, 1::2] = values.T
    for fc, row in zip(fcs, co):
        fc.keyframe_points.foreach_set("co", row)
        fc.update()


def _rebase_action(arm_obj, names, old, new) -> RebasedKeys | None:
    """Re-express every bone's rotation keys (and the root's location keys) against the new rest
    frames, all bones in one vectorised step."""
    anim = arm_obj.animation_data
    if anim is None or anim.action is None:
        return None
    curves = {(fc.data_path, fc.array_index): fc for fc in action_fcurves(anim.action, arm_obj)}

    def read(path, size):
        fcs = [curves.get((path, i)) for i in range(size)]
        if any(fc is None for fc in fcs) or len({len(fc.keyframe_points) for fc in fcs}) != 1:
            return None
        n = len(fcs[0].keyframe_points)
        co = np.empty((size, 2 * n), dtype=np.float32)
        for fc, row in zip(fcs, co):
            fc.keyframe_points.foreach_get("co", row)
        return fcs, co

    rot = [(j, read(f'pose.bones["{n}"].rotation_quaternion', 4)) for j, n in enumerate(names)]
    rot = [(j, r) for j, r in rot if r is not None]
    loc = read(f'pose.bones["{names[0]}"].location', 3)
    locations = None
    if loc is not None:
        locations = rebase_locations(loc[1][:, 1::2].T.astype(np.float64), old[0], new[0])
        _write_curves(loc[0], loc[1], locations)
    frames = {row.tobytes() for _, (_, co) in rot + ([(0, loc)] if loc is not None else []) for row in co[:, 0::2]}
    if rot and len(frames) == 1:  # every bone keyed on the same frames: one batched rebase
        idx = [j for j, _ in rot]
        q = np.stack([r[1][:, 1::2].T for _, r in rot]).astype(np.float64)  # (J,T,4)
        q2 = rebase_quaternions(q, old[idx], new[idx])
        for (_, (fcs, co)), values in zip(rot, q2):
            _write_curves(fcs, co, values)
        if len(idx) == len(names) and loc is not None:
            return RebasedKeys(q2, locations, new, loc)
        return None
    for j, (fcs, co) in rot:
        _write_curves(fcs, co, rebase_quaternions(co[:, 1::2].T.astype(np.float64), old[j], new[j]))
    return None
