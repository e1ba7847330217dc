"""A captured take shorter than asked, played on as a loop where the take itself repeats.

A take of jumping jacks, arm circles or a dribble that lasts 3 s, asked for 10 s, is not held on
its last pose for 7 s: its own cycle plays again. The cycle is ``loop_cut.best_cut``'s (the two frames
a < b whose pose relative to the root and whose velocities are most alike), with two conditions
that say the take repeats rather than merely starts and ends alike:

- the cycle is cut in the take's busy stretch (its standing start and end left out: frames whose
  largest joint step is under ``STILL`` of the take's 90th percentile), lasts ``SHORTEST_CYCLE`` s
  or more and at most ``MOST_OF_TAKE`` of that stretch, so at least two cycles were performed (a
  single front kick, standing before and after, is held), and moves on average at least ``BUSY``
  x as much a frame as the stretch does; and the cycle before or after it is the same movement
  again (poses within ``REPEAT`` x the cycle's own spread);
- the seam, frame b - 1 followed by frame a moved by the cycle's advance, steps no joint farther
  than ``SEAM_STEP`` x the 99th percentile of the take's own largest joint step per frame, and the
  heading turns by at most ``MOST_TURN`` degrees over a cycle (the cycles repeat on a straight line).

The take plays from its first frame to b - 1, then a..b - 1 again and again, each repeat moved by
the cycle's advance on the floor; the contacts repeat with the frames, so planting the whole
window (``retarget.planted_retarget``) plants the repeats as the take's own steps.

A take of one repetition of an action done over and over by its nature (``actions.REPEATED``: a
single arm circle of 1.9 s) has no second cycle to find; ``looped_repetition`` plays its busy
stretch again when the stretch ends where it began (the same seam and heading conditions): on the
spot, or moved on by the stretch's advance when its root travels faster than ``TRAVELS`` and the
action may go somewhere as it repeats (a dribble, a hop, a gait's cycle; an arm circle whose performer
stepped back once is not looped into a walk backwards: it is held).

A take of a gait (four jogging steps from standing) is looped on its steps (``looped_gait``): its
last stride, from one foot's touching down to the same foot's next, the latest such stride of either
foot, as the measured contacts say (a toe or a heel down after both were up), played again and
again moved on by its own advance (the same seam and heading conditions); its end is the frame,
within ``CONTACT_SLACK`` of the second touch-down, whose pose is nearest the first's. The take plays
from its first touch-down under way (``UNDER_WAY`` of that stride's pace), not from standing.
"""
from __future__ import annotations

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from ..motion.contacts import runs

SHORTEST_CYCLE = 0.5   # s
SHORTEST_STEP = 0.25   # s: one foot's touch-down to the other's
STEP_FADE = 8          # frames: a mirrored step starts from the pose before it, the difference faded out over these
LOWER = 12             # joints 0..11: the pelvis, spine's base and legs, which must meet at a step's seam
MOST_OF_TAKE = 0.45    # the longest cycle, as a share of the take
SEAM_STEP = 1.5        # the seam's step against the 99th percentile of the take's steps
MOST_TURN = 20.0       # degrees of heading per cycle
STILL = 0.25           # a frame whose largest step is under this x the 90th percentile stands
BUSY = 0.5             # the cycle's mean step against the busy stretch's
TRAVELS = 0.2          # m/s: a repetition whose root goes on faster than this travels (a dribble on the move)
REPEAT = 0.5           # a neighbouring cycle's pose difference against the cycle's own spread
CONTACT_SLACK = 2      # frames a measured touch-down may be off by (a stride's end is sought this near)
UNDER_WAY = 0.85       # a gait's take plays from the first touch-down going this share of its last stride's pace
FEET = ((0, 2), (1, 3))   # the contacts' columns of each foot: (ankle, toe), left then right


def looped_take(rotations, root, contacts, joints, frames: int):
    """(rotations, root, contacts, first) of a take (T,24,3,3), (T,3), (T,4) whose posed ``joints``
    (T,J,3) repeat, played on to ``frames`` (> T) frames: ``first`` frames of the take as performed,
    then its cycle repeated; None when the take does not repeat (module doc) or is long enough."""
    from .loop_cut import best_cut
    from .track import headings

    if len(rotations) >= frames:
        return None
    J = np.asarray(joints, np.float64)
    busy = _busy(J)
    if busy is None:
        return None
    steps, s, e = busy
    try:
        cut = best_cut(J[s:e], FPS, (SHORTEST_CYCLE, MOST_OF_TAKE * (e - s) / FPS))
    except ShapeMoveError:   # too short for two cycles of the shortest length
        return None
    a, b = cut.start + s, cut.end + s
    if steps[a:b].mean() < BUSY * steps[s:e - 1].mean() or not _repeated(J, a, b):
        return None
    return _played_on(rotations, root, contacts, J, steps, headings(J), a, b, b, frames)


def looped_repetition(rotations, root, contacts, joints, frames: int, travels: bool = True):
    """As ``looped_take`` for a take of one repetition (``actions.REPEATED``): its busy stretch a..b-1
    (the standing start and end left out) is the cycle, played again while its last frame steps into
    its first no farther than the take's own steps; None when it does not, or the take is long
    enough. ``travels`` False: the action is done on the spot, the cycle's advance is never added."""
    from .track import headings

    if len(rotations) >= frames:
        return None
    J = np.asarray(joints, np.float64)
    busy = _busy(J)
    if busy is None or busy[2] - busy[1] < SHORTEST_CYCLE * FPS:
        return None
    steps, a, b = busy
    r = np.asarray(root, np.float64)
    moves = travels and np.linalg.norm((r[b - 1] - r[a])[[0, 2]]) > TRAVELS * (b - 1 - a) / FPS   # moving on
    return _played_on(rotations, root, contacts, J, steps, headings(J), a, b, b - 1, frames, travel=moves)


def _busy(J):
    """(largest joint step of each frame (T-1,), s, e) of the take's busy stretch s..e-1: its
    standing start and end left out (frames whose largest step is under ``STILL`` of the 90th
    percentile); None when nothing moves."""
    steps = np.linalg.norm(np.diff(J, axis=0), axis=-1).max(-1)
    moving = np.flatnonzero(steps >= STILL * np.percentile(steps, 90))
    if len(moving) < 2:
        return None
    return steps, int(moving[0]), int(moving[-1]) + 2


def _played_on(rotations, root, contacts, J, steps, h, a: int, b: int, on: int, frames: int, travel: bool = True):
    """Frames 0..b-1, then a..b-1 over and over to ``frames``, each repeat moved by the cycle's
    advance (frame ``on``'s root and heading against frame a's: b where the take goes on past the
    cycle, else its last frame; none without ``travel``: a repetition on the spot, whose sway must
    not add up); None when the cycle turns more than ``MOST_TURN`` or its seam steps farther than
    ``SEAM_STEP`` x the take's 99th-percentile step."""
    if abs(np.degrees(np.angle(np.exp(1j * (h[on] - h[a]))))) > MOST_TURN:
        return None
    root = np.asarray(root, np.float32)
    per_frame = (b - a) / max(1, on - a)   # the last frame's root stands one frame short of the next cycle's
    advance = (root[on] - root[a]) * np.array([1.0, 0.0, 1.0], np.float32) * float(travel) * per_frame
    seam = np.linalg.norm(J[a] + advance - J[b - 1], axis=-1).max()
    if seam > SEAM_STEP * np.percentile(steps, 99):
        return None
    period = b - a
    reps = -(-(frames - b) // period)
    idx = np.concatenate([np.arange(b)] + [np.arange(a, b)] * reps)[:frames]
    k = np.concatenate([np.zeros(b)] + [np.full(period, i + 1.0) for i in range(reps)])[:frames]
    return (np.asarray(rotations)[idx], (root[idx] + k[:, None] * advance).astype(np.float32),
            np.asarray(contacts)[idx], b)


def _repeated(J, a: int, b: int) -> bool:
    """Whether the cycle a..b-1 was performed twice: the poses (relative to the root) of the cycle
    before it or after it differ from its own by at most ``REPEAT`` x how far its poses spread."""
    P = b - a
    rel = J - J[:, :1]
    cycle = rel[a:b]
    spread = np.linalg.norm(cycle - cycle.mean(0), axis=-1).mean()
    others = [rel[c:c + P] for c in (a - P, b) if c >= 0 and c + P <= len(J)]
    return any(np.linalg.norm(o - cycle, axis=-1).mean() <= REPEAT * spread for o in others)


def looped_gait(rotations, root, contacts, joints, frames: int):
    """As ``looped_take`` for a take of a gait: its last stride (module doc) played on to ``frames``
    frames; None when the take has no stride of ``SHORTEST_CYCLE`` s or more, the stride turns or its
    seam steps too far, or the take is long enough."""
    from .track import headings

    if len(rotations) >= frames:
        return None
    stride = last_stride(contacts)
    if stride is None:
        return None
    J = np.asarray(joints, np.float64)
    a, b = stride
    rel = J - J[:, :1]
    near = range(max(a + 1, b - CONTACT_SLACK), min(len(J), b + CONTACT_SLACK + 1))
    b = min(near, key=lambda k: np.linalg.norm(rel[k] - rel[a], axis=-1).mean())   # the frame a's pose comes back
    s = _under_way(root, contacts, a, b)   # the standing start left out
    J = J[s:]
    steps = np.linalg.norm(np.diff(J, axis=0), axis=-1).max(-1)
    return _played_on(np.asarray(rotations)[s:], np.asarray(root)[s:], np.asarray(contacts)[s:], J, steps,
                      headings(J), a - s, b - s, b - s, frames)


def _under_way(root, contacts, a: int, b: int) -> int:
    """The first frame of a gait's take under way: the earliest touch-down (or frame 0) from which the
    root covers a stride's time at ``UNDER_WAY`` x the last stride a..b's speed or more."""
    r = np.asarray(root, np.float64)[:, [0, 2]]
    period = b - a
    pace = np.linalg.norm(r[b] - r[a]) / period
    down = np.concatenate([touch_downs(contacts, foot) for foot in FEET])
    for s in sorted(set(down.tolist()) | {0}):
        if s >= a or np.linalg.norm(r[s + period] - r[s]) >= UNDER_WAY * pace * period:
            return min(s, a)
    return a


def looped_steps(rotations, root, contacts, joints, frames: int, mirror):
    """A gait's take of one step of each foot, no foot touching down twice (two sneaking steps from
    standing), played on to ``frames``: as performed to the end of its last step (one foot's
    touch-down to the other's), then that step's mirror image (the other foot leading) and the step
    again, over and over, each moved on by the step's advance (the mirror image's sideways part
    mirrored, so the pair goes straight on). The mirror image is taken about the vertical plane of
    the walker's heading halfway through the step (the step twists the hips one way, the mirror
    image twists them back, so each seam meets the pose it follows). ``mirror(rotations, root,
    contacts)`` mirrors frames facing +Z (``captured_takes.mirrored``). Returns (rotations, root, contacts, first) as
    ``looped_take``; None when the take is long enough, has no such step of ``SHORTEST_STEP`` s or
    more, the step turns more than ``MOST_TURN`` or a seam steps its pelvis or legs farther than
    ``SEAM_STEP`` x the take's 99th-percentile step. The arms and head need not be symmetric (a
    sneak's are not): each step starts from the pose before it, the difference faded out over
    ``STEP_FADE`` frames (``faded_in``)."""
    from ..data.mirror import mirror_joints
    from ..geometry.rotations import yaw_matrix
    from .track import headings

    if len(rotations) >= frames:
        return None
    step = last_step(contacts)
    if step is None:
        return None
    a, b = step
    J = np.asarray(joints, np.float64)
    h = headings(J)
    turn = float(np.angle(np.exp(1j * (h[b] - h[a]))))
    if abs(np.degrees(turn)) > MOST_TURN:
        return None
    mid = h[a] + turn / 2    # the step twists the hips one way, its mirror image back: mirrored about the mid heading
    to_step, back = yaw_matrix(-mid), yaw_matrix(mid)
    pivot = np.array([root[a][0], 0.0, root[a][2]])
    rot = np.array(rotations, np.float32)
    rot[:, 0] = to_step.astype(np.float32) @ rot[:, 0]
    rt = (np.asarray(root, np.float64) - pivot) @ to_step.T           # facing +Z mid-step, a over the origin
    con = np.asarray(contacts)
    m_rot, m_rt, m_con = mirror(rot[a:b], rt[a:b].astype(np.float32), con[a:b])
    adv = (rt[b] - rt[a]) * np.array([1.0, 0.0, 1.0])
    m_adv = adv * np.array([-1.0, 1.0, 1.0])
    Js = (J - pivot) @ to_step.T
    mJ = mirror_joints(Js[a:b])
    steps = np.linalg.norm(np.diff(J, axis=0), axis=-1).max(-1)
    seams = (np.linalg.norm(mJ[0] + adv - Js[b - 1], axis=-1)[:LOWER].max(),
             np.linalg.norm(Js[a] + adv + m_adv - (mJ[-1] + adv), axis=-1)[:LOWER].max())
    if max(seams) > SEAM_STEP * np.percentile(steps, 99):
        return None
    period, pair = 2 * (b - a), adv + m_adv
    reps = -(-(frames - b) // period)
    # the arms and head of a sneak are not symmetric: each block starts from the pose before it, faded out
    m_rot, o_rot = faded_in(m_rot, rot[b - 1]), faded_in(rot[a:b], m_rot[-1])
    rots = [rot[:b]] + [np.concatenate([m_rot, o_rot])] * reps
    roots = [rt[:b]] + [np.concatenate([m_rt + adv, rt[a:b] + pair]) + k * pair for k in range(reps)]
    cons = [con[:b]] + [np.concatenate([m_con, con[a:b]])] * reps
    out_rot = np.concatenate(rots)[:frames]
    out_rot[:, 0] = back.astype(np.float32) @ out_rot[:, 0]
    out_root = (np.concatenate(roots)[:frames] @ back.T + pivot).astype(np.float32)
    return out_rot, out_root, np.concatenate(cons)[:frames], b


def faded_in(rotations, before, frames: int = STEP_FADE) -> np.ndarray:
    """``rotations`` (T,J,3,3) starting from the pose ``before`` (J,3,3): each joint's difference
    from its first frame carried in and faded out (smoothstep) over ``frames`` frames."""
    from ..geometry.rotations import axis_angle_to_matrix, matrix_to_axis_angle

    rot = np.array(rotations, np.float32)
    n = min(frames, len(rot))
    delta = matrix_to_axis_angle(np.swapaxes(rot[0], -1, -2).astype(np.float64) @ np.asarray(before, np.float64))
    u = np.arange(n) / max(n, 1)
    w = 1.0 - u * u * (3.0 - 2.0 * u)
    rot[:n] = (rot[:n] @ axis_angle_to_matrix(w[:, None, None] * delta[None])).astype(np.float32)
    return rot


def last_step(contacts) -> tuple[int, int] | None:
    """(a, b): the latest step of the ``contacts`` (T,4): one foot touching down at a, the other at
    b, at least ``SHORTEST_STEP`` s later, no touch-down between; None without one."""
    downs = sorted((int(t), f) for f, foot in enumerate(FEET) for t in touch_downs(contacts, foot))
    for (a, fa), (b, fb) in zip(downs[::-1][1:], downs[::-1]):
        if fa != fb and b - a >= SHORTEST_STEP * FPS and b < len(contacts):
            return a, b
    return None


def last_stride(contacts) -> tuple[int, int] | None:
    """(a, b): the latest stride of the ``contacts`` (T,4) (columns: left ankle, right ankle, left
    toe, right toe): a foot touching down at a and again at b, at least ``SHORTEST_CYCLE`` s later;
    b < T, so frame b shows the next stride's first pose. None when no foot touches down twice."""
    best = None
    for foot in FEET:
        onsets = touch_downs(contacts, foot)
        for a, b in zip(onsets[::-1][1:], onsets[::-1]):
            if b - a >= SHORTEST_CYCLE * FPS:
                if best is None or b > best[1]:
                    best = (int(a), int(b))
                break
    return best


def touch_downs(contacts, foot) -> np.ndarray:
    """Frames where ``foot`` (its columns of the (T,4) contacts: ``FEET``) touches down: a heel or toe
    down after neither was."""
    down = (np.asarray(contacts) > 0)[:, list(foot)].any(1)
    return np.array([a for a, _ in runs(down) if a > 0], dtype=np.int64)
