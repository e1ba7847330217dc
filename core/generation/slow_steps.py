"""Slow steps: a stepping gait the words ask to go slowly ("walks slowly", "marches at a leisurely
pace"; ``pace_words.asks_slow_steps``) is played at ``pace_words.SLOW_SPEED`` over its own length.

The first ``SLOW_SPEED`` share of the decoder's joint track is resampled to the whole length
(``track.resample``) and the feet planted again (``track.replanted``): an edit, like a turn the
words name (``turn_words.py``), so the motion keeps no tokens and a new body keeps it rather than
re-decoding it. Choosing the slowest candidates instead cost the gait (limps and creeps), and a
jog or a run is not slowed (its flights would hang in the air): ``docs/prompts.md``.
"""
from __future__ import annotations

from .pace_words import SLOW_SPEED, asks_slow_steps


def slow_motion(motion, body, prompt: str, ik_refine_iters: int = 10):
    """``motion`` played at ``SLOW_SPEED`` over its own length when ``prompt`` asks a stepping gait
    to go slowly (``asks_slow_steps``); the motion itself otherwise."""
    from .track import Track, replanted, resample, track_of

    if not asks_slow_steps(prompt) or motion.num_frames < 4:
        return motion
    track = track_of(motion)
    n = len(track.joints)
    keep = max(2, int(round(n * SLOW_SPEED)))
    return replanted(motion, body, resample(Track(track.joints[:keep], track.contacts[:keep]), n), ik_refine_iters)
