"""Slow steps: a gait the words ask to go slowly ("walks slowly", "marches at a leisurely pace",
"jogs at an easy pace") goes ``pace_words.SLOW_SPEED`` times as fast over its own length.

A stepping gait (``pace_words.asks_slow_steps``: a walk, a march, a sneak: no flight phase) is
played slower: the first ``SLOW_SPEED`` share of the decoder's joint track is resampled to the whole
length (``track.resample``). A jog or a run (``pace_words.asks_slow_flight``) keeps its cadence and
its flights, which played slower would hang in the air, and takes shorter strides instead
(``stride_scale.scaled_strides`` at ``SLOW_SPEED``: the root's path and the feet's reach shortened
together). Either way the feet are planted again (``track.replanted``): an edit, like a turn the
words name (``turn_words.py``), so the motion keeps no tokens and a new body keeps it rather than
re-decoding it. Choosing the slowest candidates instead cost the gait (limps and creeps):
``docs/prompts.md``.
"""
from __future__ import annotations

from .pace_words import SLOW_SPEED, asks_slow_flight, asks_slow_steps


def slow_motion(motion, body, prompt: str, ik_refine_iters: int = 10):
    """``motion`` at ``SLOW_SPEED`` of its speed over its own length when ``prompt`` asks a gait to
    go slowly (module doc); the motion itself otherwise."""
    from .stride_scale import scaled_strides
    from .track import Track, replanted, resample, track_of

    if motion.num_frames < 4:
        return motion
    track = track_of(motion)
    if asks_slow_steps(prompt):
        n = len(track.joints)
        keep = max(2, int(round(n * SLOW_SPEED)))
        return replanted(motion, body, resample(Track(track.joints[:keep], track.contacts[:keep]), n), ik_refine_iters)
    if asks_slow_flight(prompt):
        return replanted(motion, body, Track(scaled_strides(track.joints, SLOW_SPEED), track.contacts), ik_refine_iters)
    return motion
