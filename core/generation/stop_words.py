"""Stopping: "takes three steps forward and stops" walks three steps and then stands.

The training data has no caption of standing still, so the T5 writes a gait on to the end: "a
person walks forward" -> "a person stands still" as a timeline kept walking (seed 0) or slowed to
0.24 m/s (seed 1). The codec itself knows standing, though: some codes, repeated, decode to a body
standing still, and the decoder's own transition from walking codes into them brings the body to
a halt within about half a second, feet planted. So a prompt that says the gait stops is generated
without its stop clause, its codes are cut after the step the words count (or at half the length
when they name no count), and the model's standing code fills the rest of the length (``STAND_SECONDS``
of it when no length was asked; the gait then goes at least ``GOING_SECONDS`` first: "he jogs to the
corner and stops" went 0.5 m, half of the model's 1.8 s, the start of a jog from standing, before it
stood); the whole is decoded again as one sequence. The motion keeps those tokens, so a new body decodes the same stop.
A timeline's segment that only asks to stand still ("stands still", "waits", "pauses";
``plan.words.Words.stand_still``) is that code too (``sequence._segment``).

- The stop: "and stops", "then stops", "comes to a stop", "halts", "stands still", "stops walking"
  after the gait ("stops" alone, or "without stopping", "non-stop": nothing).
- The count: "three steps", "a step", "a couple of steps" (2), "a few steps" (3), digits; a step is
  a foot strike (a new contact of either foot) after the first frame. A count alone stops too:
  "takes three steps forward", "she takes a step back" walk that many steps and stand (none other
  than a gait named: "takes two steps and spins" is left alone).
- A distance: "walks 3 metres forward", "runs ten meters and stops", "jogs 20 feet" (metres, meters,
  m, feet, ft, yards): the cut is the code where the body is that far from where it started in a
  straight line (``distance_cut``; of the codes from two before it to the next, ``distance_keeps``,
  the one whose motion, decoded again on its body, stands nearest the distance). A body's height ("six feet tall", "a six foot man") is no distance.
  With no length asked, the motion is made long enough for a slow walk to get there. Of the
  samples, those whose path reaches the distance in the length (``reaching``; on the body asked:
  the distance scaled by its leg against the samples' body's) are the ones the TMA chooses among
  (the longest when none does): a slow sample chosen left a 5 ft 1 woman 0.42 m short.
- The standing code (``standing_code``): of the codes the memory's real clips hold for at least
  ``REST_RUN`` codes in a row, the one whose repetition decodes with the least joint speed and
  root travel, wrists below the shoulders (arms down); found once per model.

    w = read_words("a man takes three steps forward and stops")   # plan/words.py
    w.gait_text, w.steps                                          # ("a man takes three steps forward", 3)
"""
from __future__ import annotations

from collections import Counter

import numpy as np
import torch

from .gait_steps import contact_strikes
from .pace_words import path_length

REACH_SLACK = 0.1          # m: a gait this close to the distance has got there
DISTANCE_PACE = 0.7        # m/s: with no length asked, a distance is given time for this slow a walk ...
DISTANCE_SECONDS = 60.0    # ... up to this long (the longest length a prompt may ask)
REST_RUN = 4       # codes in a row: a code held this long in a real clip is a candidate standing code
REST_PROBE = 10    # codes the candidate is repeated for when it is decoded
DISTANCE_EARLIER = 2   # codes before a distance's cut also tried (``distance_keeps``)
STAND_SECONDS = 1.6   # standing after the stop when the model decides the length (none was asked)
GOING_SECONDS = 3.0   # ... and at least this long going before it, when no steps or distance are counted


def standing_code(memory, vae) -> int | None:
    """The code that decodes to a body standing still (module doc); None without a memory."""
    if memory is None or not len(memory):
        return None
    held = Counter()
    for tokens in memory.clip_tokens:
        t = np.asarray(tokens)
        if len(t) == 0:
            continue
        starts = np.r_[0, np.flatnonzero(np.diff(t)) + 1, len(t)]
        for a, b in zip(starts[:-1], starts[1:]):
            if b - a >= REST_RUN and int(t[a]) < vae.quantizer.codebook_size:
                held[int(t[a])] += 1
    if not held:
        return None
    from ..motion.features import joints_from_features
    from .decode import decode_features

    best, cost = None, np.inf
    with torch.no_grad():
        for code, _ in held.most_common(12):
            J = joints_from_features(decode_features([code] * REST_PROBE, vae, np.zeros(10, np.float32)).numpy())
            if (J[:, [20, 21], 1] > J[:, [16, 17], 1]).any():   # a hand above its shoulder: not at rest
                continue
            c = float(np.linalg.norm(np.diff(J, axis=0), axis=2).mean() + np.linalg.norm(J[-1, 0, [0, 2]] - J[0, 0, [0, 2]]))
            if c < cost:
                best, cost = code, c
    return best


def stop_cut(contacts, steps: int | None, n: int, down: int) -> int | None:
    """How many of a gait's ``n`` codes are kept: up to the code that lands its ``steps``-th foot
    strike (``gait_steps.contact_strikes`` of the planted ``contacts``: a foot already coming down
    at the start is no step taken) and the next; half of them when ``steps`` is None; None when the
    gait strikes fewer times than counted."""
    if steps is None:
        return max(1, n // 2)
    strikes = contact_strikes(contacts)
    if len(strikes) < steps:
        return None
    return min(n, strikes[steps - 1] // down + 2)


def from_start(joints) -> np.ndarray:
    """(T,) how far (m) the root of (T, 22, 3) ``joints`` is from its first position, in a straight
    line on the floor plane."""
    root = np.asarray(joints, np.float64)[:, 0, [0, 2]]
    return np.linalg.norm(root - root[0], axis=1)


def distance_cut(joints, metres: float, n: int, down: int) -> int | None:
    """How many of a gait's ``n`` codes are kept: up to the code whose frames bring the root
    ``metres`` from its first position (``from_start``; within ``REACH_SLACK``) in the (T, 22, 3)
    ``joints``; None when it never gets that far."""
    far = np.flatnonzero(from_start(joints) >= metres - REACH_SLACK)
    return None if not len(far) else min(n, int(far[0]) // down + 1)


def reaching(feats: list, metres: float, among: np.ndarray) -> np.ndarray:
    """(N,) bool: of the candidates ``among`` (bool), those whose root path over their (T,263)
    features (metres a frame, ``features.py``) is at least ``metres``; where none is, the one (or
    those) of the longest path."""
    path = np.array([path_length(f) for f in feats])
    if not among.any():
        return among
    return among & (path >= min(metres, path[among].max()))


def distance_keeps(keep: int, n: int) -> list[int]:
    """The cuts tried around a distance's ``keep`` (of ``n`` codes): the body slows to a halt over
    the standing code's first codes, further the faster it went (a run overshoots by about a code
    and a half), so from two codes before ``keep`` to the one after it."""
    return sorted({min(n, max(1, k)) for k in range(keep - DISTANCE_EARLIER, keep + 2)})


def standing_after(codes, keep: int, rest: int, stand: int | None = None) -> list[int]:
    """The first ``keep`` of ``codes``, then ``rest`` to their length (``stand`` codes of it
    instead when given: a length the model chose)."""
    codes = [int(c) for c in codes]
    return codes[:keep] + [rest] * (len(codes) - keep if stand is None else stand)


OVERSHOOT = 0.04   # a cut gait that stands further than this share past the distance takes shorter strides
# (it then keeps no tokens: a cut within it keeps them, so a new body decodes it again)


def shortened_to(motion, body, metres: float, ik_refine_iters: int = 10):
    """``motion`` (a gait cut at the code nearest ``metres``, then standing) brought back to the
    distance where it overshoots by more than ``OVERSHOOT``: its root's steps and the feet's reach
    shortened together (``stride_scale.scaled_strides``, its cadence kept) and the feet planted
    again (``track.replanted``). A code is a fifth of a second, so the cut alone lands up to a
    quarter of a stride past the mark (3.25 m of 3 m on "an old man"). Unchanged otherwise."""
    from .stride_scale import scaled_strides
    from .track import Track, replanted, track_of

    gone = float(from_start(motion.joints)[-1])
    if gone <= metres * (1 + OVERSHOOT) or motion.num_frames < 4:
        return motion
    track = track_of(motion)
    return replanted(motion, body, Track(scaled_strides(track.joints, metres / gone), track.contacts), ik_refine_iters)
