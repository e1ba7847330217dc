"""An action that is no gait, asked slowly ("an old man sits down slowly", "she waves slowly"):
played at ``SLOW_ACTION`` of its speed.

A gait asked slowly goes slower (``slow_steps.py``); any other action was played at its captured
or generated speed and "slowly" named as not used. Here the motion's moving part (up to where it
holds still: a captured sit or kick held on its last pose) is resampled longer (``track.resample``)
and planted again (``track.replanted``):

- the model's length (no length asked): the moving part lasts ``1 / SLOW_ACTION`` as long and the
  motion with it (a 3.7 s sit becomes 5.5 s), the still end kept;
- a length asked: the motion keeps it, the moving part taking up its still end, as far as
  ``1 / SLOW_ACTION`` (a 1.1 s sit held 2.9 s in 4 s is played over 1.6 s); a motion that moves to
  its last frame, or holds still too briefly to be played ``MIN_GAIN`` longer, keeps its speed
  (slowed, its end would be cut), and says so.

    motion = slowed(motion, body, read_words("an old man sits down slowly"), keep_length=False)   # longer
"""
from __future__ import annotations

import numpy as np

from .track import Track, replanted, resample, track_of

SLOW_ACTION = 0.67   # of its speed: an action asked slowly
MIN_GAIN = 1.05      # a moving part made less than this much longer is left as it is (said when a length is asked)
STILL = 1e-3         # m: a frame whose joints all move less than this from the one before holds still


def moving_frames(joints) -> int:
    """The frames of (T, J, 3) ``joints`` before their still end (at least 2)."""
    j = np.asarray(joints, dtype=np.float64)
    step = np.abs(np.diff(j, axis=0)).max(axis=(1, 2))
    moving = np.flatnonzero(step >= STILL)
    return max(2, int(moving[-1]) + 2) if len(moving) else 2


def slowed(motion, body, words, keep_length: bool, ik_refine_iters: int = 10):
    """``motion`` played at ``SLOW_ACTION`` of its speed when the plan's ``words``
    (``plan.words.Words``) ask its action slowly (module doc); ``keep_length``: a length was asked,
    which it keeps (else the model's, which grows). The motion itself otherwise, or when nothing would
    change."""
    if not words.slowly:
        return motion
    track = track_of(motion)
    n = len(track)
    active = moving_frames(track.joints)
    longer = int(round(active / SLOW_ACTION))
    if keep_length:
        total, longer = n, min(longer, n)     # the still end taken up
    else:
        total = n - active + longer           # the still end kept after it
    if longer < MIN_GAIN * active:   # a length asked that the action fills: nothing to take up
        if keep_length:
            motion.notes = list(motion.notes) + [f"not played slowly: the action fills the {n / motion.fps:.1f} s "
                                                 "asked (a longer length leaves it room)"]
        return motion
    moved = resample(Track(track.joints[:active], track.contacts[:active]), longer)
    still = total - longer
    joints = np.concatenate([moved.joints, np.repeat(track.joints[-1:], still, 0)])
    contacts = np.concatenate([moved.contacts, np.repeat(track.contacts[-1:], still, 0)])
    out = replanted(motion, body, Track(joints, contacts), ik_refine_iters, measured=bool(motion.contacts_measured))
    out.provenance = motion.provenance
    out.notes = list(motion.notes) + [f"played slowly: the action over {longer / motion.fps:.2f} s "
                                      f"instead of {active / motion.fps:.2f} s"]
    return out
