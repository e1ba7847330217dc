"""A pose the words keep: arms held raised ("walks with both arms raised", "a woman stands, hands
raised"), a squat held low ("squats and holds it", "crouches down and stays there").

The raise-hand takes and samples raise the arms and lower them again within a couple of seconds;
words that describe a state (``plan.vocabulary.ARMS_HELD``: "with both arms raised", "keeps his
hand up", "holding his arms above his head") want the raise kept. The motion is played to the
frame where a wrist is highest above the pelvis, and that pose is held for the rest:

- two things at once ("runs with both arms raised"): the arms track alone (``parts.py``); the
  legs go on, the held arms ride on their chest;
- the raise alone (every action named is a gesture: "a woman stands with her arms raised"): the
  whole body, replanted (``track.replanted``; a captured take's measured contacts as they are).

The squat takes go down and come back up in a second or two; words that hold it
(``plan.vocabulary.HELD_LOW``: "holds it", "holds the position", "stays down") play the squat to the
frame where the pelvis is lowest and hold that pose, the whole body replanted.

    track = held_from_peak(track)
    motion = held_motion(motion, body, ik_refine_iters)              # the arms at their top
    motion = held_motion(motion, body, ik_refine_iters, low=True)    # the pelvis at its lowest
"""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from ..scene.motion_file import Motion
from .captured_takes import without_last_pose_held
from .track import Track, fitted, replanted, track_of

WRISTS = (20, 21)
PELVIS = 0


def peak_frame(joints) -> int:
    """The first frame where a wrist is highest above the pelvis, of (T,>=22,3) joints (Y up)."""
    j = np.asarray(joints, np.float64)
    above = j[:, WRISTS, 1].max(1) - j[:, PELVIS, 1]
    return int(np.argmax(above))


def lowest_frame(joints) -> int:
    """The first frame where the pelvis is lowest, of (T,>=22,3) joints (Y up)."""
    return int(np.argmin(np.asarray(joints, np.float64)[:, PELVIS, 1]))


def held_from(track: Track, frame: int) -> Track:
    """``track`` played to ``frame`` and held there for the rest of its length (the same track when
    the frame is its last)."""
    p = max(int(frame), 1)
    if p >= len(track) - 1:
        return track
    return fitted(Track(track.joints[:p + 1], track.contacts[:p + 1]), len(track))


def held_from_peak(track: Track) -> Track:
    """``track`` played to its ``peak_frame`` and held there for the rest of its length."""
    return held_from(track, peak_frame(track.joints))


def held_motion(motion: Motion, body, ik_refine_iters: int = 10, low: bool = False) -> Motion:
    """``motion`` played to its ``peak_frame`` (``low``: its ``lowest_frame``) and held there,
    planted again; it keeps no tokens (an edit of its frames) and says from when the pose is held."""
    track = track_of(motion)
    frame = lowest_frame(track.joints) if low else peak_frame(track.joints)
    held = held_from(track, frame)
    if held is track:
        return motion
    # a captured take: its measured contacts planted as they are
    out = replanted(motion, body, held, ik_refine_iters, measured=bool(motion.contacts_measured))
    out.provenance = motion.provenance
    out.notes = (without_last_pose_held(motion.notes) + [low_note(frame)] if low
                 else list(motion.notes) + [held_note(track)])
    return out


def held_note(track: Track) -> str:
    """What the motion says of a track held at its peak."""
    return f"the raised arms are held from {peak_frame(track.joints) / FPS:.1f} s (the words keep them raised)"


def low_note(frame: int) -> str:
    """What the motion says of a squat held at its lowest from ``frame``."""
    return f"the squat is held at its lowest from {frame / FPS:.1f} s (the words keep it there)"
