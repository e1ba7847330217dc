"""The stance foot rolls over its ball: in late stance the heel rises and the foot pivots about the
ball joint, which stays where it was planted.

A planted foot held flat cannot follow a root that travels as far as a real walker's: once the hip
has passed over the foot, the leg cannot reach back to a heel still on the floor, so ``pin_feet``'s
soft IK stops short and the heel is dragged forward (stance slide). A real foot rolls instead. Per
stance (a run of the ball joint's contact, ``motion.contacts``) with a planted heel:

* **pivot** ``P``: where the flat foot puts its ball joint: the heel's anchor plus the body's own
  foot length (ankle to ball, ``L``) toward the ball's anchor where the heel's run starts, so the
  ball does not move when the roll starts (``pin_feet`` aims the foot the same way); the ball's
  target is moved by that much for the whole run (and its fade). A run planted piece by piece
  along a slide (``plant.anchor_track``) carries the pivot with its ball; taking the ball's anchor
  at the run's first frame instead put a sliding squat's ball 0.7 m from the foot. A ball planted
  more than ``MISFIT`` from ``P`` (a heel and a ball planted at the means of runs the decoded foot
  slid along, 13 cm out of the foot's length) is not rolled over: the move, undone where the
  run ends, made the foot leap there.
* **pitch** ``theta``: the foot turns about the horizontal axis through ``P`` across the foot (a
  sagittal rotation); the heel (ankle joint) then lies on a circle of radius ``L`` about ``P``,
  rising and moving forward. Per frame, the smallest ``theta`` that brings the heel within the
  leg's reach of the hip (``reach`` of the leg's length, where ``pin_feet`` still lands a joint
  exactly), once the hip has passed over the ball (a body standing on straight legs does not
  roll); the pitch of the first such frame is reached by a ramp from mid-stance (the frame where
  the hip is closest to the heel), so the heel does not jump up. After the heel's contact ends,
  at least the pitch the IK pose already has (the decoder's own toe-off). It changes by at most
  ``ROLL_STEP`` a frame and never decreases within a stance (a heel that rose stays up until the
  foot leaves), unless the heel lands again before the foot leaves (a step walked backwards lands
  toe first): then it comes down to the floor by the frame it lands.
* **steering**: the leg pass (``pin_feet``) still steers a rolled heel, onto its rolled target,
  with full weight (also after the decoder released the heel, until the ball leaves).
* **contacts**: the contacts the planted Motion reports follow what its heels do: a heel stays
  in contact only while the roll keeps it on the floor (within ``LIFT_TOL`` of its flat
  height, where it moves forward by well under a millimetre per frame); from there to the end of
  the stance it is off the floor and released.
* **toes**: the toe segment (the ball joint's rotation) turns back by ``theta``, so the toes stay
  flat on the floor while the heel rises (the foot bends at the ball).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ShapeMoveError
from ..motion.contacts import runs

MAX_ROLL = np.deg2rad(60.0)   # the most the heel is pitched up about the ball
LIFT_TOL = 0.005              # m: a heel higher than this above its flat height is off the floor
ROLL_STEP = np.deg2rad(10.0)  # the most the heel's pitch changes in a frame
MISFIT = 0.05                 # m: a ball planted further than this from where the flat foot puts it is not rolled over
UP = np.array([0.0, 1.0, 0.0])


@dataclass
class Roll:
    targets: np.ndarray    # (T,22,3) the planting targets with rolled heels and the balls on their pivots
    weights: np.ndarray    # (T,4) leg-pass weights (``pin_feet``): a rolled heel keeps weight 1
    contacts: np.ndarray   # (T,4) uint8: a heel's contact released where the roll lifts it off the floor
    toe: np.ndarray        # (T,2,3) world rotation vector (axis * theta) the toes of each leg undo


def _frame(heel, pivot) -> tuple[np.ndarray, np.ndarray, float]:
    """Heel and ball anchors (3,) -> (e1, e2, L0): e1 the unit vector from the pivot to the heel,
    e2 the unit vector across it in the foot's vertical plane, pointing up; L0 their distance."""
    v = np.asarray(heel, np.float64) - np.asarray(pivot, np.float64)
    L0 = float(np.linalg.norm(v))
    if L0 < 1e-6:
        raise ShapeMoveError("a planted heel and ball on the same point: the foot has no length to roll over")
    e1 = v / L0
    e2 = UP - (UP @ e1) * e1
    n = np.linalg.norm(e2)
    if n < 1e-6:
        raise ShapeMoveError("a planted foot standing upright: it cannot roll over its ball")
    return e1, e2 / n, L0


def reach_angle(hip, pivot, e1, e2, foot: float, reach: float) -> np.ndarray:
    """Smallest pitch theta >= 0 (rad) per frame that puts the heel, at ``pivot + foot *
    (cos theta e1 + sin theta e2)``, within ``reach`` (m) of ``hip`` (N,3); where no pitch reaches
    it, the pitch that comes closest (capped at ``MAX_ROLL``).

    |hip - heel|^2 <= reach^2  <=>  a cos theta + b sin theta >= k, with a, b the hip's offset
    from the pivot along e1, e2 and k = (|hip - pivot|^2 + foot^2 - reach^2) / (2 foot)."""
    d = np.asarray(hip, np.float64) - np.asarray(pivot, np.float64)
    a, b = d @ e1, d @ e2
    k = ((d * d).sum(-1) + foot ** 2 - reach ** 2) / (2 * foot)
    rho, alpha = np.hypot(a, b), np.arctan2(b, a)
    theta = alpha - np.arccos(np.clip(k / np.maximum(rho, 1e-12), -1.0, 1.0))
    theta = np.where(a >= k, 0.0, theta)                  # the flat foot is within reach already
    return np.clip(theta, 0.0, MAX_ROLL)


def pitch_of(ankle, ball, e1) -> np.ndarray:
    """(N,3) ankle and ball positions -> (N,) pitch (rad) of the foot relative to the flat foot (e1,
    from the ball to the heel): how far the heel is already turned up, in the foot's own vertical
    plane whichever way it faces (measured against e1's direction instead, a foot turned a
    quarter away from its planted heading, on a circle, read as pitched by 60 degrees)."""
    v = np.asarray(ankle, np.float64) - np.asarray(ball, np.float64)
    level = np.arctan2(v[:, 1], np.linalg.norm(v[:, [0, 2]], axis=1))
    return level - np.arctan2(e1[1], np.linalg.norm(e1[[0, 2]]))


def roll_feet(posed, targets, contacts, weights, rest, reach: float, legs, fade: int) -> Roll:
    """The stance feet rolled over their balls (see the module doc).

    posed (T,22,3) the body after the whole-body IK (its hips stay where they are: the leg pass
    turns only the legs), targets (T,22,3) from ``plant_targets`` (floor at y = 0), contacts (T,4)
    of joints 7, 8, 10, 11, weights (T,4) their leg-pass weights (``plant.contact_weights``, fading
    over ``fade`` frames), rest (>=22,3) the body's rest joints, ``reach`` the fraction of the
    leg's length within which ``pin_feet`` lands a joint exactly (its ``soft_reach``), ``legs``
    ``plant.LEGS`` (hip, knee, ankle, ball joint, heel and ball contact columns per leg)."""
    pos = np.asarray(posed, np.float64)
    tgt = np.array(targets, dtype=np.float64)
    c = np.asarray(contacts).astype(bool)
    rest = np.asarray(rest, np.float64)
    T = len(tgt)
    if pos.shape[:2] != (T, 22) or c.shape != (T, 4) or weights.shape != (T, 4):
        raise ShapeMoveError(f"roll_feet needs (T,22,3) poses and targets and (T,4) contacts, got {pos.shape}, "
                             f"{tgt.shape}, {c.shape}")
    weights = np.array(weights, dtype=np.float64)
    out_c = c.copy()
    toe = np.zeros((T, 2, 3))
    for leg, (hip, knee, ankle, ball, kh, kt) in enumerate(legs):
        foot = float(np.linalg.norm(rest[ball] - rest[ankle]))
        limb = reach * float(np.linalg.norm(rest[knee] - rest[hip]) + np.linalg.norm(rest[ankle] - rest[knee]))
        heel_runs = runs(c[:, kh])
        for sb, eb in runs(c[:, kt]):
            over = [(s, e) for s, e in heel_runs if s < eb and e > sb and e <= eb]
            if not over:
                continue
            s, e = over[-1]                                   # the heel run the foot rolls off
            t = np.arange(max(s, sb), eb)
            A, B = tgt[t[0], ankle].copy(), tgt[t[0], ball].copy()   # the heel and ball planted together
            if np.linalg.norm(B - A) < 1e-6:
                continue
            P = A + foot * (B - A) / np.linalg.norm(B - A)
            if np.linalg.norm(P - B) > MISFIT:                # heel and ball planted a foot apart they
                continue                                      # are not: a foot sliding, nothing to roll over
            _move_ball(tgt, weights[:, kt], c[:, kt], ball, sb, eb, P - B, fade)
            e1, e2, _ = _frame(A, P)
            P = P + (tgt[t, ball] - tgt[t[0], ball])          # (N,3): a ball planted piece by piece along
            A = A + (tgt[t, ball] - tgt[t[0], ball])          # a slide (plant.anchor_track) carries the pivot
            fwd = (P[0] - A[0]) * [1.0, 0.0, 1.0]
            ahead = ((pos[t, hip] - P) * fwd).sum(-1) > 0     # the hip has passed over the ball
            theta = np.where(ahead, reach_angle(pos[t, hip], P, e1, e2, foot, limb), 0.0)
            on = np.flatnonzero(theta > 0)
            if len(on):                                       # the heel starts rising at mid-stance (the
                mid = int(np.argmin(np.linalg.norm(pos[t, hip] - A, axis=-1)))   # leg at its shortest)
                if mid < on[0]:
                    theta[mid:on[0]] = theta[on[0]] * np.arange(on[0] - mid) / (on[0] - mid)
            after = t >= e                                    # the decoder already lifted the heel
            theta = np.where(after, np.maximum(theta, np.clip(pitch_of(pos[t, ankle], pos[t, ball], e1),
                                                              0.0, MAX_ROLL)), theta)
            theta = np.maximum.accumulate(theta)
            for i in range(1, len(theta)):                    # the heel rises at most ROLL_STEP a frame
                theta[i] = min(theta[i], theta[i - 1] + ROLL_STEP)
            again = [hs for hs, _ in heel_runs if e < hs <= eb + fade]
            if again:                                         # the heel lands again before the foot leaves
                theta = np.minimum(theta, ROLL_STEP * np.clip(again[0] - t, 0, None))   # (a step walked
                # backwards, toe first): it comes down to the floor by then
            rolled = theta > 0
            if not rolled.any():
                continue
            t, theta, P = t[rolled], theta[rolled], P[rolled]
            u1, u2 = _headed(e1, tgt[t, ankle] - P)           # the foot turned as its heel's target turns
            tgt[t, ankle] = P + foot * (np.cos(theta)[:, None] * u1 + np.sin(theta)[:, None] * u2)
            weights[t, kh] = 1.0
            out_c[t[tgt[t, ankle, 1] - A[0, 1] > LIFT_TOL], kh] = False   # the heel is off the floor
            axis = np.cross(u1, u2)                           # turning e1 toward e2: the heel up
            toe[t, leg] = theta[:, None] * axis
    return Roll(targets=tgt, weights=weights, contacts=out_c.astype(np.uint8), toe=toe)


def _headed(e1, heel) -> tuple[np.ndarray, np.ndarray]:
    """The flat foot's direction e1 (3,) (pivot to heel) per frame (N,3), turned about the vertical
    toward the heel's own target ``heel`` (N,3, from the pivot): a decoded foot may turn on its
    ball (a turn on the spot) or along a slide planted piece by piece (shuffling round a circle);
    held to e1, the heel was pinned a quarter turn away from the foot and leapt 0.3 m when the ball
    left. And the unit vectors up across it (e2 per frame)."""
    flat = np.linalg.norm(e1[[0, 2]])
    h = np.asarray(heel, np.float64)[:, [0, 2]]
    n = np.linalg.norm(h, axis=1, keepdims=True)
    own = np.where(n > 1e-3, h / np.maximum(n, 1e-12), e1[[0, 2]] / max(flat, 1e-12))
    u1 = np.stack([own[:, 0] * flat, np.full(len(own), e1[1]), own[:, 1] * flat], axis=1)
    u2 = UP[None] - (u1 @ UP)[:, None] * u1
    return u1, u2 / np.linalg.norm(u2, axis=1, keepdims=True).clip(1e-12)


def _move_ball(tgt, w, on, ball: int, s: int, e: int, shift, fade: int) -> None:
    """The ball's target of run [s, e) moved by ``shift`` (3,), in place; its fade frames (those
    not in another run: ``on`` (T,) its contact) by the fraction ``w`` of it they were planted with."""
    tgt[s:e, ball] += shift
    for t in [*range(max(s - fade, 0), s), *range(e, min(e + fade, len(tgt)))]:
        if not on[t]:
            tgt[t, ball] += w[t] * shift

