"""Re-decode a generated rig's motion for its new body after a shape change (debounced).

A rig built from a motion file that can be made again for another body ("shapemove_motion_file",
"shapemove_has_tokens": motion tokens, or a take played by its own rotations, which is planted
again, ``Motion.remakeable``) gets a "redecode" job DEBOUNCE seconds after the last shape change (``shape_sync.on_betas_changed``
calls ``schedule``). When the job returns and the rig still has the betas the job was made for,
the rig's action is replaced by the re-decoded motion (``apply_motion``); a stale answer (the
sliders moved again meanwhile) schedules a new job instead.
"""
from __future__ import annotations

import bpy
import numpy as np

from ..core.scene.motion_file import load_motion
from ..core.scene.rig_data import motion_channels_z_up
from . import grounding, paths
from .job_submit import submit_job
from .jobs import report_error
from .keyframes import write_pose_action
from .preferences import setting
from .rig_state import current_betas, rig_body_spec

DEBOUNCE = 0.6  # s of quiet after the last slider move before a job starts
MOTION_FILE_KEY = "shapemove_motion_file"
HAS_TOKENS_KEY = "shapemove_has_tokens"   # the rig's motion can be made again for a new body (Motion.remakeable)

_scheduled: set[str] = set()
_inflight: dict[str, tuple] = {}  # rig name -> (job id, betas the job decodes for)


def wants_redecode(rig) -> bool:
    scene = bpy.context.scene
    auto = getattr(getattr(scene, "shapemove", None), "auto_redecode", True)
    return bool(rig is not None and auto and rig.get(HAS_TOKENS_KEY) and rig.get(MOTION_FILE_KEY))


def schedule(rig) -> bool:
    """(Re)start the debounce timer for ``rig``; False when the rig has nothing to re-decode."""
    if not wants_redecode(rig):
        return False
    _scheduled.add(rig.name)
    if bpy.app.timers.is_registered(_fire):
        bpy.app.timers.unregister(_fire)
    bpy.app.timers.register(_fire, first_interval=DEBOUNCE)
    return True


def pending() -> set[str]:
    """Rig names waiting for the timer or for a job's answer."""
    return set(_scheduled) | set(_inflight)


def _fire():
    names = sorted(_scheduled)
    _scheduled.clear()
    for name in names:
        rig = bpy.data.objects.get(name)
        if rig is not None and name not in _inflight:
            try:
                submit(rig)
            except Exception as exc:  # noqa: BLE001  (a timer must not raise into Blender)
                print(f"ShapeMove: could not re-decode {name}: {exc}")
        elif rig is not None:
            _scheduled.add(name)  # after the running job answers
    return None


def submit(rig) -> str:
    """Start the redecode job for the rig's current betas -> job id."""
    betas = current_betas(rig)
    params = {"motion": rig[MOTION_FILE_KEY], "betas": betas.tolist(), "body": rig_body_spec(rig),
              "model": setting("active_model") or None,
              "out": str(paths.new_motion_path(f"{rig.name}_redecoded"))}
    name = rig.name
    jid = submit_job("redecode", params, label=f"re-decode {name}",
                     on_result=lambda msg: _answered(name, betas, msg),
                     on_error=lambda msg: _failed(name, msg))
    _inflight[name] = (jid, betas)
    return jid


def _failed(name, msg) -> None:
    _inflight.pop(name, None)
    report_error(f"re-decoding {name} failed: {msg['message']}")


def _answered(name, betas, msg) -> None:
    _inflight.pop(name, None)
    rig = bpy.data.objects.get(name)
    if rig is None or msg.get("cancelled"):
        return
    if np.abs(current_betas(rig) - betas).max() > 1e-4:
        schedule(rig)  # the shape changed while the job ran
        return
    if name in _scheduled:
        return  # a newer change is waiting for its timer
    apply_motion(rig, load_motion(msg["result"]["path"]))
    rig["shapemove_redecoded_file"] = msg["result"]["path"]


def apply_motion(rig, motion) -> bpy.types.Action:
    """Replace the rig's action with ``motion``'s keys (same action name; the old one is removed
    when nothing else uses it), the travel on what the rig was built to carry it with (its root
    motion: the pelvis, the object, a root bone, or none for in place; ``animation_rig``); a timeline
    rig's strips play the new action with their own timing (``animation_rig.replay_strips``); a
    loop's new action repeats as the old one did (``animation_rig.cycle_action``). The
    bones must already sit on the rest joints of motion.betas. (A decoded motion is already
    grounded on the body's mesh by core's decode.)"""
    from ..core.scene.root_motion import rig_channels
    from .animation_rig import ROOT_MOTION_KEY, cycle_action, key_travel, replay_strips

    mode = str(rig.get(ROOT_MOTION_KEY, "PELVIS"))
    ch = rig_channels(motion, mode)
    rotations, transl = motion_channels_z_up(ch.poses, ch.transl)
    names = rig["shapemove_joint_names"].split("\n")
    grounding.forget_contacts(rig)  # a new motion: its contacts are detected at the next shape change
    anim = rig.animation_data
    old = anim.action if anim is not None else None
    name = old.name if old is not None else f"{rig.name}_motion"
    if old is None:   # a timeline's strips play its action: that is the one replaced
        strips = [s for t in anim.nla_tracks for s in t.strips if s.action is not None] if anim is not None else []
        old = strips[0].action if strips else None
        name = old.name if old is not None else name
    action = write_pose_action(rig, rotations, transl, motion.fps, names, name + "_new")
    key_travel(bpy.context, rig, action, ch.travel, mode)
    if ch.cycle is not None:
        cycle_action(rig, action, ch.cycle)
    replay_strips(rig, action)
    if old is not None and old.users == 0:
        bpy.data.actions.remove(old)
    action.name = name
    bpy.context.scene.frame_set(bpy.context.scene.frame_current)
    return action


def unregister() -> None:
    if bpy.app.timers.is_registered(_fire):
        bpy.app.timers.unregister(_fire)
    _scheduled.clear()
    _inflight.clear()
