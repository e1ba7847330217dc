"""Planted feet: contact-aware IK targets and grounding on the mesh soles.

Mocap retargeted by IK onto another body keeps a few cm of joint error, so feet that stood still
in the capture slide and hover on the body, and a body grounded by its lowest foot *joint* sinks
(the soles are below the joints). These steps fix that:

1. ``plant_targets``: before IK, move the targets of the joints in contact (heels = ankles,
   toes = ball joints, ``core.motion.contacts``) onto one fixed point per contact run: its XZ is
   the run's mean, its height the joint's sole offset on the body (``soles.sole_offsets``), so
   the sole touches y = 0. A run along which the joint slides further than ``SLIDE`` (a decoded
   body drifting over a foot it says is planted: 0.4 m in a squat) is planted piece by piece
   (``anchor_track``): each piece's point within ``PIECE`` of where the joint is, the change
   from one piece's point to the next spread over ``FADE`` frames. One point for such a run was
   up to 0.5 m from the foot at the run's ends, and the foot leapt there in a frame (0.76 m where
   the decoded ankle moved at most 0.04 m). The source floor is estimated from the contacts
   themselves. Runs of a joint at most ``GAP`` frames apart (a decoder's contact flickering off for
   a frame: no foot steps that fast) are planted as one (``bridged``): each planted at its own point,
   the foot moved between them in one frame. The change fades out over ``FADE`` frames around each
   run so the targets stay continuous; in a gap between two runs the two fades are blended by their
   weights (taking the nearer run's whole moved the foot from one's change to the other's in a
   frame). IK
   (``ik.solve_ik``, which weights the ankles and feet most) then lands the feet there.
   ``fade_down=False`` (decoding): the fade moves a foot sideways or up, never down.
2. ``pin_feet`` (decoding): the whole-body IK spreads its misses over all joints, so a contact
   leg is then turned (soft two-bone IK) to land its planted heel and ball exactly where the
   leg reaches (a planted joint still steps ~0.26 mm per frame on average on retargeted test clips).
   Before it, ``foot_roll.roll_feet`` lets a stance foot roll over its ball where the hip has
   travelled past the leg's reach of the flat heel: the heel's target pitches up about the pinned
   ball, the toes stay flat, and the heel's contact is released once it is off the floor.
3. ``ground_shift``: after posing, a per-frame vertical shift of the whole body computed on the
   mesh (``soles.GroundProbe``): on frames with a contact, the lowest vertex of the foot in
   contact goes to y = 0; between contact frames the shift is interpolated (a jump keeps its
   flight); no frame leaves any probe point under the floor.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..constants import FPS
from ..geometry.rotations import rotation_between
from ..motion.contacts import CONTACT_IDS, runs

FADE = 4          # frames over which a planted target blends back into the mocap target
EASE = 0.3        # of a contact joint's largest decoded step: the most its planting change moves in a frame
MIN_EASE = 0.002  # m: ... at least (a foot the decoder holds still can still be put on the floor)
LEG_EASE = EASE / 2   # of the ankle's largest step: the most ``pin_feet``'s move of a leg changes in a frame
# where no joint of it stays planted (the knee swings about twice as far as the ankle is moved)
SLIDE = 0.3       # m: a contact run's joint sliding further than this is planted piece by piece ...
PIECE = 0.05      # m: ... each piece as far as the joint slides from the piece's first frame
GAP = 2           # frames: contact runs of a joint this close are planted as one (no step is that short)


def source_floor(joints, contacts, sole_offsets) -> float:
    """Height of the floor in the source's coordinates: the median over contact events of the
    contact joint's height minus its sole offset (without contacts: the lowest such value)."""
    j = np.asarray(joints, dtype=np.float64)[:, CONTACT_IDS, 1] - np.asarray(sole_offsets)[None]
    c = np.asarray(contacts).astype(bool)
    return float(np.median(j[c])) if c.any() else float(j.min())


def anchor_track(xz, slide: float = SLIDE, piece_len: float = PIECE, fade: int = FADE) -> np.ndarray:
    """(n,2) where a contact run's joint is planted each frame, from its (n,2) floor positions
    ``xz``: one point, the run's mean, unless the joint slides further than ``slide`` from its first
    frame; then the run cut into pieces along which the joint stays within ``piece_len`` of the
    piece's first frame, each piece planted at its mean, the steps between pieces spread over
    ``fade`` frames (a moving mean) and then eased to the joint's own largest step in the run (the
    plant never moves faster than the foot it holds)."""
    xz = np.asarray(xz, np.float64)
    n = len(xz)
    piece = np.zeros(n, int)
    if np.linalg.norm(xz - xz[0], axis=1).max() <= slide:
        return np.repeat(xz.mean(0, keepdims=True), n, axis=0)
    first = 0
    for i in range(1, n):
        if np.linalg.norm(xz[i] - xz[first]) > piece_len:
            first = i
            piece[i:] += 1
    if piece[-1] == 0:
        return np.repeat(xz.mean(0, keepdims=True), n, axis=0)
    means = np.stack([xz[piece == k].mean(0) for k in range(piece[-1] + 1)])
    track = means[piece]
    pad = np.pad(track, ((fade // 2, fade - 1 - fade // 2), (0, 0)), mode="edge")
    kernel = np.ones(fade) / fade
    track = np.stack([np.convolve(pad[:, c], kernel, mode="valid") for c in range(2)], axis=1)
    return eased(track, largest_step(xz))


def largest_step(track) -> float:
    """The longest move of a (T,D) track between two frames (0 for one frame)."""
    x = np.asarray(track, np.float64)
    return float(np.linalg.norm(np.diff(x, axis=0), axis=1).max()) if len(x) > 1 else 0.0


def eased(change, rate: float, free=None, fixed=None) -> np.ndarray:
    """(T,D) a change per frame -> the same with no step between frames longer than ``rate`` (m)
    plus ``free`` (T-1,) (where it may move as fast as asked: within a run, the change that holds a
    foot still while the decoded one slides): the mean of the change limited from the start
    forwards and from the end backwards (each moves at most that far a frame toward the change, so
    their mean does too), a jump eased over the frames on both sides of it, not after it.
    ``fixed`` (T,) bool: those frames keep their change exactly and only the others are eased,
    forwards and then backwards (a foot lands on its plant exactly, moving toward it beforehand)."""
    x = np.asarray(change, np.float64)
    allow = rate + (np.zeros(max(len(x) - 1, 0)) if free is None else np.asarray(free, np.float64))
    if fixed is not None:
        out = x.copy()
        keep = np.asarray(fixed, bool)
        for t in range(1, len(x)):
            if not keep[t]:
                out[t] = _toward(out[t - 1], out[t], allow[t - 1])
        for t in range(len(x) - 2, -1, -1):
            if not keep[t]:
                out[t] = _toward(out[t + 1], out[t], allow[t])
        return out
    fwd, bwd = x.copy(), x.copy()
    for t in range(1, len(x)):
        fwd[t] = _toward(fwd[t - 1], x[t], allow[t - 1])
    for t in range(len(x) - 2, -1, -1):
        bwd[t] = _toward(bwd[t + 1], x[t], allow[t])
    return (fwd + bwd) / 2


def _toward(prev, want, most: float):
    d = want - prev
    n = float(np.linalg.norm(d))
    return want if n <= most else prev + d * (most / n)


def lifted(change, rate: float, free=None) -> np.ndarray:
    """(T,) a vertical change -> the least one at or above it that moves at most ``rate`` (m) plus
    ``free`` (T-1,) a frame: a foot pulled down onto the floor is let up (or down) gradually at a
    run's edges, never lowered further than asked (the swing foot beside a run keeps its height)."""
    v = np.asarray(change, np.float64).copy()
    allow = rate + (np.zeros(max(len(v) - 1, 0)) if free is None else np.asarray(free, np.float64))
    for t in range(1, len(v)):
        v[t] = max(v[t], v[t - 1] - allow[t - 1])
    for t in range(len(v) - 2, -1, -1):
        v[t] = max(v[t], v[t + 1] - allow[t])
    return v


def bridged(spans, gap: int = GAP) -> list[tuple[int, int]]:
    """Contact runs [(start, end)] with those apart by at most ``gap`` frames joined into one."""
    out: list[list[int]] = []
    for s, e in spans:
        if out and s - out[-1][1] <= gap:
            out[-1][1] = e
        else:
            out.append([s, e])
    return [(s, e) for s, e in out]


def plant_targets(joints, contacts, sole_offsets, fade: int = FADE, fade_down: bool = True) -> tuple[np.ndarray, float]:
    """joints (T,22,3) mocap targets, contacts (T,4) of joints 7, 8, 10, 11, sole_offsets (4,) of
    the body the IK will fit -> (targets (T,22,3) with the floor at y = 0 and planted contact
    joints, source floor height that was subtracted). ``fade_down`` False: the fade around a run
    moves the joint horizontally and up, never down (a foot still descending to, or rising from,
    its plant keeps its own height: lowering it would drag the swing foot toward the floor)."""
    tgt = np.array(joints, dtype=np.float64)
    T = len(tgt)
    floor = source_floor(tgt, contacts, sole_offsets)
    tgt[..., 1] -= floor
    for k, j in enumerate(CONTACT_IDS):
        corr = np.zeros((T, 3))
        planted = np.zeros(T, bool)
        edges: dict[int, list] = {}   # frame outside a run -> [(weight, its run edge's change)]
        run_of = np.full(T, -1)
        for s, e in bridged(runs(np.asarray(contacts)[:, k])):
            run_of[s:e] = s
            xz = anchor_track(tgt[s:e, j][:, [0, 2]], fade=max(fade, 1))
            anchor = np.stack([xz[:, 0], np.full(e - s, float(sole_offsets[k])), xz[:, 1]], axis=1)
            corr[s:e] = anchor - tgt[s:e, j]
            planted[s:e] = True
            for d in range(1, fade + 1):  # fade the change of the run's edges out over `fade` frames
                w = 1.0 - d / (fade + 1)
                for t, edge in ((s - d, s), (e - 1 + d, e - 1)):
                    if 0 <= t < T:
                        step = anchor[edge - s] - tgt[edge, j]
                        if not fade_down:
                            step[1] = max(step[1], 0.0)
                        edges.setdefault(t, []).append((w, step))
        for t, near in edges.items():   # between two runs: their edges' changes blended by weight
            if not planted[t]:
                w = np.array([x for x, _ in near])
                corr[t] = w.max() * (w[:, None] * np.array([x for _, x in near])).sum(0) / w.sum()
        if planted.any() and T > 1:   # no planting change faster than the joint's own decoded steps allow
            rate = max(EASE * largest_step(tgt[:, j]), MIN_EASE) / np.sqrt(2)
            held = planted[1:] & planted[:-1] & (run_of[1:] == run_of[:-1])   # steps within one run
            free_xz = np.where(held, np.linalg.norm(np.diff(corr[:, [0, 2]], axis=0), axis=1), 0.0)
            free_y = np.where(held, np.abs(np.diff(corr[:, 1])), 0.0)
            corr[:, [0, 2]] = eased(corr[:, [0, 2]], rate, free_xz)
            corr[:, 1] = (lifted(corr[:, 1], rate, free_y) if not fade_down
                          else eased(corr[:, 1:2], rate, free_y)[:, 0])
        tgt[:, j] += corr
    return tgt, floor


SOFT_REACH = 0.99  # of the leg's length: beyond it ``pin_feet`` approaches full stretch asymptotically
# (0.97 until 2026-11-27: planted feet slid a third more, 0.34 against 0.21 mm per frame on validation
# takes retargeted, with no fewer knee jerks: docs/codec.md#planted-legs-reach-further-soft-reach-099)
LEGS = ((1, 4, 7, 10, 0, 2), (2, 5, 8, 11, 1, 3))   # hip, knee, ankle, foot joints; heel, toe contact column


def contact_weights(contacts, fade: int = FADE) -> np.ndarray:
    """(T,4) contacts -> (T,4) weights: 1 in contact, fading linearly to 0 over ``fade`` frames
    on either side of each run (as ``plant_targets`` fades its targets)."""
    c = np.asarray(contacts).astype(bool)
    w = c.astype(np.float64)
    T = len(c)
    for k in range(c.shape[1]):
        for s, e in runs(c[:, k]):
            for d in range(1, fade + 1):
                for t in (s - d, e - 1 + d):
                    if 0 <= t < T:
                        w[t, k] = max(w[t, k], 1.0 - d / (fade + 1))
    return w


def pin_feet(rotations, transl, rest, parents, targets, weights, soft_reach: float = SOFT_REACH,
             toe=None) -> np.ndarray:
    """The contact-aware IK pass: after the whole-body IK, each leg's hip and knee are turned
    (two-bone IK in the knee's own bending plane) so that a planted heel (ankle joint) lands on its
    target, and the ankle turned so that a planted ball joint does too, its sole flat (no roll onto
    an edge: ``aimed_flat``, by the weaker of the two weights); where the ball is planted more
    firmly than the heel (toe-off) the foot moves without turning so that the ball lands.
    ``weights`` (T,4) from ``contact_weights``: the
    leg moves that fraction of its miss (1 in contact: exactly on target where the leg reaches).
    rotations (T,24,3,3) local, transl (T,3), rest (24,3), targets (T,22,3) ->
    new local rotations (T,24,3,3); frames without weight are unchanged. ``toe`` (T,2,3) world
    rotation vectors (left, right leg), non-zero where the foot rolls over its ball
    (``foot_roll.roll_feet``): there the ball joint's rotation lays the toes flat on the floor
    (``flat_toes``). The knee's move is eased like the ankle's (no faster a frame than ``EASE`` of
    the knee target's largest step) where a plant is not held exactly: in the fades, and in the
    heel-led frames where the heel is beyond the soft reach or rolling up (a ball leading is held
    exactly); the ankle is then aimed at its goal from the eased knee."""
    import torch

    from ..geometry.torch_ops import forward_kinematics

    rot = np.array(rotations, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    with torch.no_grad():
        pos, G = forward_kinematics(torch.as_tensor(rot), torch.as_tensor(rest, dtype=torch.float64)[None]
                                    .expand(len(rot), -1, -1), parents)
    pos, G = pos.numpy() + np.asarray(transl, dtype=np.float64)[:, None], G.numpy()
    tgt = np.asarray(targets, dtype=np.float64)
    rest = np.asarray(rest, dtype=np.float64)
    for hip, knee, ankle, foot, kh, kt in LEGS:
        t = np.flatnonzero((w[:, kh] > 0) | (w[:, kt] > 0))
        if not len(t):
            continue
        held = np.maximum(w[:, kh], w[:, kt]) >= 1.0            # planted frames
        led = (w[:, kh] >= w[:, kt]) & (w[:, kh] > 0)           # heel-led (else the ball leads: toe-off)
        wh, wt = w[t, kh, None], w[t, kt, None]
        a = pos[t, ankle]
        lead = np.clip(1.0 - np.maximum(wt - wh, 0.0), 0.0, 1.0)   # the heel's share, moving from heel-led
        want = lead * (a + wh * (tgt[t, ankle] - a)) + (1 - lead) * (a + wt * (tgt[t, foot] - pos[t, foot]))
        # to ball-led as the heel's weight fades below the ball's (switching at once moved the ankle by
        # the two targets' disagreement in one frame)
        move = np.zeros((len(rot), 3))
        move[t] = want - a
        move = eased(move, max(LEG_EASE * largest_step(tgt[:, ankle]), MIN_EASE), fixed=held)   # planted: exact
        # elsewhere it changes no faster than the targets' own steps allow (a rolled heel let go at
        # once when its ball left moved the ankle and knee 0.12 m in a frame)
        t = np.flatnonzero((np.linalg.norm(move, axis=1) > 1e-9) | (w[:, kh] > 0) | (w[:, kt] > 0))
        h, k, a, b = pos[t, hip], pos[t, knee], pos[t, ankle], pos[t, foot]
        wh, wt = w[t, kh, None], w[t, kt, None]
        heel = led[t, None]
        want = a + move[t]
        l1, l2 = np.linalg.norm(rest[knee] - rest[hip]), np.linalg.norm(rest[ankle] - rest[knee])
        v = want - h
        d = np.linalg.norm(v, axis=-1, keepdims=True).clip(1e-9)
        reach, soft = l1 + l2, soft_reach * (l1 + l2)         # soft IK: no knee snap near full stretch
        dc = np.where(d > soft, soft + (reach - soft) * (1 - np.exp(-(d - soft) / (reach - soft))), d)
        dc = dc.clip(abs(l1 - l2) + 1e-4, reach - 1e-4)
        vh = v / d
        a2 = h + vh * dc                                        # where the ankle goes (reachable)
        ua = (a - h) / np.linalg.norm(a - h, axis=-1, keepdims=True).clip(1e-9)
        side = (k - h) - ((k - h) * ua).sum(-1, keepdims=True) * ua    # the knee's bend direction, off the
        side = side - (side * vh).sum(-1, keepdims=True) * vh          # pose's own leg (off the line to the
        # target instead, it flipped where the target passed the knee: 0.38 m in a frame)
        lateral = G[t, hip][:, :, 0]                            # straight leg: bend about the hip's x axis
        fallback = np.cross(lateral, vh)
        fallback *= np.sign((fallback * (k - h)).sum(-1, keepdims=True) + 1e-12)
        side = np.where(np.linalg.norm(side, axis=-1, keepdims=True) > 1e-4, side, fallback)
        side /= np.linalg.norm(side, axis=-1, keepdims=True).clip(1e-12)
        cos = ((l1 ** 2 + dc ** 2 - l2 ** 2) / (2 * l1 * dc)).clip(-1, 1)
        k2 = h + l1 * (cos * vh + np.sqrt(1 - cos ** 2) * side)
        # the knee's move eased as the ankle's is: near full stretch it is several times the ankle's
        # (a captured toe-off's leg straightened to its planted ball snapped back bent, 0.27 m in a frame)
        bend = np.zeros((len(rot), 3))
        bend[t] = k2 - k
        exact = held.copy()                                    # planted and exact, unless heel-led (the
        exact[t] &= ~led[t] | (d[:, 0] <= soft)                # foot aimed at its ball below) with the heel
        if toe is not None:                                    # missed anyway (beyond the soft reach) or
            exact &= ~(led & np.abs(np.asarray(toe)[:, 0 if kh == 0 else 1]).any(-1))   # rolling up
        bend = eased(bend, max(EASE * largest_step(tgt[:, knee]), MIN_EASE), fixed=exact)[t]
        k2 = h + l1 * _unit(k + bend - h)
        a2 = k2 + l2 * _unit(a2 - k2)                          # the ankle aimed at its goal from there
        R1 = rotation_between(k - h, k2 - h)
        R2 = rotation_between(np.einsum("nij,nj->ni", R1, a - k), a2 - k2)
        g_hip, g_knee = R1 @ G[t, hip], R2 @ R1 @ G[t, knee]
        g_ankle = G[t, ankle]                                   # the foot keeps its world orientation...
        both = (heel & (wt > 0))[:, 0]
        if both.any():                                          # ...unless heel and ball are planted
            b_want = b[both] + wt[both] * (tgt[t[both], foot] - b[both])
            g_ankle = g_ankle.copy()
            g_ankle[both] = rotation_between(b[both] - a[both], b_want - a2[both]) @ G[t[both], ankle]
            flat = aimed_flat(rest[foot] - rest[ankle], b_want - a2[both])   # the sole on the floor: a
            g_ankle[both] = _slerp(g_ankle[both], flat, np.minimum(wh[both], wt[both])[:, 0])   # foot rolled
            # onto its edge in the source lifted the body by its edge's depth, settling a frame later
        parent = G[t, parents[hip]]
        rot[t, hip] = parent.transpose(0, 2, 1) @ g_hip
        rot[t, knee] = g_hip.transpose(0, 2, 1) @ g_knee
        rot[t, ankle] = g_knee.transpose(0, 2, 1) @ g_ankle
        if toe is not None:
            leg = 0 if kh == 0 else 1
            r = np.flatnonzero(np.abs(np.asarray(toe)[t, leg]).sum(-1) > 0)
            if len(r):   # the toes lie flat as in the rest pose, turned to their heading: undoing the
                # roll's pitch alone left the pitch the pose already had, toes 3 cm under the floor
                rot[t[r], foot] = g_ankle[r].transpose(0, 2, 1) @ flat_toes(g_ankle[r] @ rot[t[r], foot])
    return rot


def _unit(v) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True).clip(1e-12)


def aimed_flat(rest_dir, want) -> np.ndarray:
    """(N,3,3) world rotations of a foot without roll (its rest orientation turned about the vertical,
    then pitched about the horizontal across it) that take the rest ankle-to-ball direction
    ``rest_dir`` (3,) to the directions ``want`` (N,3)."""
    from ..geometry.rotations import yaw_matrix

    want = np.asarray(want, np.float64)
    r = np.asarray(rest_dir, np.float64)
    Y = yaw_matrix(np.arctan2(want[:, 0], want[:, 2]) - np.arctan2(r[0], r[2]))
    return rotation_between(Y @ r, want) @ Y


def _slerp(a, b, w) -> np.ndarray:
    """(N,3,3) rotations from ``a`` toward ``b`` by the fractions ``w`` (N,) (``rotations.slerp``)."""
    from ..geometry.rotations import matrix_to_quaternion, quaternion_to_matrix, slerp

    return quaternion_to_matrix(slerp(matrix_to_quaternion(a), matrix_to_quaternion(b), w))


def flat_toes(g_toe) -> np.ndarray:
    """(N,3,3) world rotations of a toe segment -> the rest pose's orientation (toes flat on the
    floor) turned about the vertical to the same heading (the direction its forward axis, +z,
    points along the floor)."""
    from ..geometry.rotations import yaw_matrix

    fwd = np.asarray(g_toe, np.float64)[:, :, 2]
    return yaw_matrix(np.arctan2(fwd[:, 0], fwd[:, 2]))


MAX_FLIGHT = 10   # frames (0.5 s at 20 fps, a 30 cm jump): longer flights are missed steps, unless they jump
MAX_JUMP = 20     # frames (1 s): the longest stretch without contact that can still be a jump
JUMP_RISE = 0.08  # m: a jump's lowest point rises at least this far over the floor
GRAVITY = 9.81
HOVER = 0.10      # m: a stretch without contact longer than a jump whose lowest point is this low stands


def _jumps(heights, fps: float = FPS) -> bool:
    """Whether a stretch without contact, between two contacts, whose lowest point is at ``heights``
    (m over the floor, contacts' grounding interpolated) is a jump: at most ``MAX_JUMP`` frames,
    rising from near the floor (half its peak at either end) to ``JUMP_RISE`` or more, and no
    higher than a ballistic flight of that length can (g t^2 / 8). A body floating for seconds, or
    higher than its time in the air allows, is a decoder that missed its steps."""
    h = np.asarray(heights, dtype=np.float64)
    peak = float(h.max())
    return (len(h) <= MAX_JUMP and peak >= JUMP_RISE and max(h[0], h[-1]) <= peak / 2
            and peak <= GRAVITY * (len(h) / fps) ** 2 / 8)


def hovering(heights, support) -> np.ndarray:
    """(T,) bool: the frames of a stretch without contact longer than a jump lasts (``MAX_JUMP``)
    where the body's lowest point (``heights``, on the floor the contacts around it set) is within
    ``HOVER`` of the floor, in a stretch that is that low for at least half its frames (a climber on
    a box is higher most of the time). Nothing stays in the air that long that low: the feet rest on
    the floor where the contacts missed them (a dancer on the balls of the feet, whose toes' contact
    the detector never saw; a capture whose floor rises under the last steps), and the body hovered
    3-6 cm over it for seconds."""
    h = np.asarray(heights, dtype=np.float64)
    out = np.zeros(len(h), bool)
    for s, e in runs(~np.asarray(support, bool)):
        low = h[s:e] < HOVER
        if e - s > MAX_JUMP and low.mean() >= 0.5:   # mostly that low: not a climb onto something
            out[s:e] = low
    return out


def ground_shift(per_foot, lowest_all, contacts, max_flight: int | None = None, hover: bool = False) -> np.ndarray:
    """(T,) vertical shift that grounds a posed body on its mesh.

    per_foot (T,2) lowest vertex of the left/right foot, lowest_all (T,) lowest point of the body,
    contacts (T,4) of joints 7, 8, 10, 11. Frames where a foot is in contact: that foot's lowest
    vertex (the lower of two) goes to 0. Other frames: the shift is interpolated between contact
    frames (held at the ends). No contact at all: one shift for the clip, lowest point on 0.
    ``hover`` (what the rig plays, ``plant_motion``): then, in a stretch without contact longer than
    a jump lasts, the frames with the lowest point within ``HOVER`` of the floor put it on the floor
    (``hovering``; the frames higher up, a leap, interpolated between them). The dataset builder
    grounds without it (``ClipProcessor.pose_on``), so the built clips, and the weights trained on
    them, stay as they are.
    Finally every frame is lifted where needed so that no point is below the floor.
    ``max_flight`` (frames): a stretch without contact longer than that cannot be a flight phase
    (predicted contacts missed a step): its lowest point goes to the floor instead, unless it rises
    and falls as a jump does (``_jumps``: a decoded "jumps up" is in the air for 12-16 frames). None
    (measured mocap contacts): every stretch keeps its interpolated height, e.g. climbing."""
    c = np.asarray(contacts).astype(bool)
    foot_on = np.stack([c[:, 0] | c[:, 2], c[:, 1] | c[:, 3]], axis=1)        # left, right
    support = foot_on.any(1)
    low_all = np.asarray(lowest_all, dtype=np.float64)
    t = np.arange(len(c))
    lowest_contact = np.where(foot_on, np.asarray(per_foot, dtype=np.float64), np.inf).min(1)
    if support.any():
        shift = np.interp(t, t[support], -lowest_contact[support])
    else:
        shift = np.full(len(c), -low_all.min())
    near = hovering(low_all + shift, support) if hover else np.zeros(len(c), bool)
    if near.any():   # a stretch standing over the floor without contact: its lowest point on it
        known = support | near
        shift = np.interp(t, t[known], np.where(support, -lowest_contact, -low_all)[known])
    if max_flight is not None:
        for s, e in runs(~support):
            if e - s > max_flight and not (0 < s and e < len(c) and _jumps(low_all[s:e] + shift[s:e])):
                shift[s:e] = -low_all[s:e]
    return np.maximum(shift, -low_all)


GATE_HEIGHT = 0.08   # m: a predicted contact whose sole is higher than this is not planted
BODY_SMOOTH = 1.5    # frames (Gaussian sigma) of ``smooth_body`` for a decoded motion (``decode.motion_from_joints``)


def smooth_body(joints, sigma: float = BODY_SMOOTH) -> np.ndarray:
    """(T,22,3) decoded joints -> the same with every joint but the ankles and feet (which
    ``plant_targets`` pins) Gaussian-smoothed over time (``sigma`` frames). The zero-moment point
    follows the CoM's second derivative: 1-2 mm of decoder jitter per frame at 20 fps moves it by
    centimetres, out of the base of support (HUMOS's dynamic stability)."""
    from ..motion.skeleton_ops import gaussian_smooth

    j = np.array(joints, dtype=np.float64)
    body = [i for i in range(j.shape[1]) if i not in CONTACT_IDS]
    if sigma > 0 and len(j) > 1:
        j[:, body] = gaussian_smooth(j[:, body], sigma)
    return j


@dataclass
class Planted:
    rotations: np.ndarray   # (T,24,3,3) local rotations
    transl: np.ndarray      # (T,3) as BodyModel.forward: posed joints = FK(rest) + transl
    contacts: np.ndarray    # (T,4) uint8 of joints 7, 8, 10, 11 (after gating; rolled heels released)
    ik_error_cm: float      # mean distance of the posed joints to ``joints`` (floor removed)


def gate_contacts(joints, contacts, sole_offsets, max_height: float = GATE_HEIGHT) -> np.ndarray:
    """Predicted contacts (e.g. a decoder's contact channels) kept only where the joint's sole is
    within ``max_height`` of the floor that the contacts imply (``source_floor``) and where the joint
    moves as slowly as a resting foot (``contacts.slow_enough``: a decoded foot that glides at walking
    pace while its channel says contact is not pinned, or its leg leaps where the pin lets go); runs
    shorter than 2 frames dropped. (T,22,3), (T,4) -> (T,4) uint8."""
    from ..motion.contacts import MIN_RUN, slow_enough

    c = np.asarray(contacts).astype(bool)
    j = np.asarray(joints, dtype=np.float64)
    h = j[:, CONTACT_IDS, 1] - np.asarray(sole_offsets)[None] - source_floor(j, c, sole_offsets)
    c &= (h < max_height) & slow_enough(j, FPS)
    for k in range(4):
        for s, e in runs(c[:, k]):
            if e - s < MIN_RUN:
                c[s:e, k] = False
    return c.astype(np.uint8)


def plant_motion(body, betas, joints, contacts, refine_iters: int = 10, gate: bool = True,
                 max_flight: int | None = MAX_FLIGHT, smooth: float = 0.0, pin: bool = True,
                 soft_reach: float = SOFT_REACH) -> Planted:
    """Joint positions (T,22,3) (e.g. decoded by the SA-VAE) -> rotations and translation of
    ``body`` with ``betas`` whose feet in ``contacts`` (T,4) are planted and whose mesh stands on
    the floor: ``plant_targets`` + ``ik.solve_ik`` + ``ground_shift`` on the body's sole probe.
    ``gate``: drop contacts whose sole is far above the floor first (``gate_contacts``).
    ``max_flight``: see ``ground_shift`` (None for known contacts, e.g. a retargeted source's).
    ``smooth`` > 0: ``smooth_body`` with that sigma (frames) first. ``pin``: after the IK, the
    contact-aware leg pass ``pin_feet`` puts the planted joints on their targets (the whole-body
    IK spreads its misses over all joints, so a planted foot would otherwise slide by millimetres to
    centimetres where the decoded body drifts away from it); before it the stance feet roll over
    their balls where the leg cannot reach a flat heel (``foot_roll.roll_feet``), and the contacts
    returned have those heels released where they leave the floor. ``soft_reach``: ``pin_feet``'s soft limit
    (of the leg's length; closer to 1 lands straighter legs on their targets, e.g. animation edits)."""
    import torch

    from .ik import solve_ik
    from .soles import GroundProbe

    b = np.asarray(betas, dtype=np.float32).reshape(-1)
    probe = GroundProbe(body, b)
    j = smooth_body(joints, smooth) if smooth > 0 else np.asarray(joints, dtype=np.float64)
    c = gate_contacts(j, contacts, probe.sole_offsets) if gate else np.asarray(contacts, np.uint8)
    targets, floor = plant_targets(j, c, probe.sole_offsets, fade_down=False)
    with torch.no_grad():
        rest = body.rest_joints(torch.as_tensor(b)[None])[0].numpy()
    ik = solve_ik(targets, rest, refine_iters=refine_iters)
    if pin:
        from .foot_roll import roll_feet

        roll = roll_feet(_posed(ik, rest, body.parents), targets, c, contact_weights(c), rest, soft_reach, LEGS, FADE)
        ik.rotations = pin_feet(ik.rotations, ik.transl, rest, body.parents, roll.targets, roll.weights, soft_reach,
                                toe=roll.toe)
        c = roll.contacts   # the heels the feet rolled off the floor are released
    transl = np.asarray(ik.transl, dtype=np.float64).copy()
    per_foot, _, low = probe.lowest(ik.rotations, transl)
    shift = ground_shift(per_foot, low, c, max_flight=max_flight, hover=True)  # predicted contacts can miss steps
    if smooth > 0:   # the body was smoothed: so is its vertical shift, downward only (no added float,
        # the peaks a per-frame shift puts into the pelvis height shaken off; never under the floor)
        from ..motion.skeleton_ops import gaussian_smooth

        shift = np.maximum(np.minimum(gaussian_smooth(shift, smooth), shift), -low)
    if len(j) > 1:   # where the foot that grounds the body changes (a heel landing after its toe) the
        # body is let down over frames, never under the floor (at once, it dropped 4 cm in a frame)
        shift = lifted(shift, max(EASE * largest_step(j[:, 0]), MIN_EASE))
    transl[:, 1] += shift
    posed = _posed(ik, rest, body.parents)   # error against the input joints (floor removed)
    posed[..., 1] += shift[:, None]
    ref = j - [0.0, floor, 0.0]
    err = float(np.linalg.norm(posed - ref, axis=-1).mean()) * 100
    return Planted(rotations=np.asarray(ik.rotations, np.float32), transl=transl.astype(np.float32),
                   contacts=c, ik_error_cm=err)


def _posed(ik, rest, parents) -> np.ndarray:
    import torch

    from ..geometry.torch_ops import forward_kinematics

    with torch.no_grad():
        pos, _ = forward_kinematics(torch.as_tensor(ik.rotations, dtype=torch.float64),
                                    torch.as_tensor(rest, dtype=torch.float64)[None].expand(len(ik.rotations), -1, -1),
                                    parents)
    return pos[:, :22].numpy() + np.asarray(ik.transl, dtype=np.float64)[:, None]


def contacts_from_features(features) -> np.ndarray:
    """(T,263) HumanML3D features (de-normalized) -> (T,4) uint8 contacts of joints 7, 8, 10, 11
    from the 4 contact channels (> 0.5)."""
    from ..motion.contacts import FEATURE_ORDER
    from ..motion.features import feature_slices

    f = np.asarray(features, dtype=np.float64)
    return (f[:, feature_slices["contacts"]] > 0.5)[:, FEATURE_ORDER].astype(np.uint8)
