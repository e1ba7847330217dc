"""Slow steps: a gait the words ask to go slowly ("walks slowly", "marches at a leisurely pace",
"jogs at an easy pace") goes ``pace_words.SLOW_SPEED`` times as fast over its own length.

A stepping gait (``plan.words.Words.slow_steps``: a walk, a march, a sneak: no flight phase) is
played slower: the first ``SLOW_SPEED`` share of the decoder's joint track is resampled to the whole
length (``track.resample``). A jog or a run (``Words.slow_flight``) keeps its cadence and
its flights, which played slower would hang in the air, and takes shorter strides instead
(``stride_scale.scaled_strides`` at ``SLOW_SPEED``: the root's path and the feet's reach shortened
together). Either way the feet are planted again (``track.replanted``): an edit, like a turn the
words name (``turn_words.py``), so the motion keeps no tokens and a new body plants it again by its rotations rather than
re-decoding it. Choosing the slowest candidates instead cost the gait (limps and creeps):
``docs/prompts.md``.
"""
from __future__ import annotations

from .pace_words import SLOW_SPEED


def slow_motion(motion, body, words, ik_refine_iters: int = 10):
    """``motion`` at ``SLOW_SPEED`` of its speed over its own length when the plan's ``words``
    (``plan.words.Words``) ask a gait to go slowly (module doc); the motion itself otherwise."""
    from .stride_scale import scaled_strides
    from .track import Track, replanted, resample, track_of

    if motion.num_frames < 4:
        return motion
    track = track_of(motion)
    if words.pace == "slow" and not words.slow_flight:
        n = len(track.joints)
        keep = max(2, int(round(n * SLOW_SPEED)))
        return replanted(motion, body, resample(Track(track.joints[:keep], track.contacts[:keep]), n), ik_refine_iters)
    if words.slow_flight:
        return replanted(motion, body, Track(scaled_strides(track.joints, SLOW_SPEED), track.contacts), ik_refine_iters)
    return motion
