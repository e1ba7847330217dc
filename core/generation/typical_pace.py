"""The typical pace of a gait: a prompt that names one walk, jog or run and asks nothing of its pace
("a person runs forward", "a man walks") goes at the pace the training data's plain captures of
that gait go at, on the body asked for.

The T5's samples and the captured takes of a plain gait spread widely in speed (walks from 0.8 to
1.2 m/s, jogs at 2.1-2.4 m/s against 1.56 captured), and the TMA that chooses among them hardly
tells a brisk one from a slow one. So after the choice, a motion whose root speed (``motion.root_speed.mean_speed``) is more than ``TOLERANCE``
above its gait's typical speed is brought down to it (by at most ``MAX_CHANGE``): a walk (no
flight phase) is played slower, the way the words' "slowly" is done (``slow_steps.py``: the first
share of its joint track resampled to the whole length); a jog or a run keeps its cadence and its
flights and takes shorter strides (``stride_scale.scaled_strides``). A motion slower than typical
is kept as it is: playing a walk faster, walking on in its own stride where its frames ran out,
changed the walks that path following and speed edits are made from past their bars (an s-curve
followed 0.75 m off, a walk at 2x sliding 0.77 mm a frame), so a slow chosen walk stays slow.
Instead a captured take slower than ``SLOW_TAKE`` of the typical speed (on its performer's body)
does not compete for a plain gait (``slow_take``): the data's walks include strolls, which the TMA
chose for "a man walks" as readily as plain walks (median 0.93x typical with them, 0.97x without).
A take of a jog faster than halfway to the run's typical speed does not compete either, for a plain
jog or one asked slowly (``fast_take``): it runs.
Nor does a take that stops or circles (``unplain_take``: held on its last pose for more than
``MOST_HELD`` of the window, or its root's path not ``straight``, the typical speeds' own test of a
straight capture): a 1.9 s jog around a bend, then standing, was "a person jogs" at 0.48x.
A jog asked fast ("a quick jog", "jogs quickly") was chosen at 2.7-3.6 m/s, a run's pace (2.87):
it is brought down to no faster than halfway between the jog's and the run's typical speeds
(``FAST_UP_TO``), so it stays a jog. The feet are planted again (``track.replanted``). Nothing
else is retimed when the words ask a pace ("quickly"),
a distance, a number of steps, a stop, a course, a turn, a direction other than forward, a count,
two things at once or a side (``plan.words.Words``); the user's ``--speed`` applies after.

The typical speeds are a table in the model folder (``TABLE``, listed in its manifest), written
by ``python tools/typical_pace.py --data data/built --model weights/default``: per gait the median
speed of the training split's straight captures of it in the performer's plain way (``style:
normal``; for jog, which has none, its unstyled captures) on the average body. On another body the
speed is scaled by its leg's length against the average body's (a taller walker's strides are
longer at the same cadence, as the dataset's average-body copies scale strides by the pelvis's
height). A model folder without the table retimes nothing.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from .pace_words import gait_speed

FORMAT = "shapemove-typical-pace/1"
STRAIGHT = 0.9   # a straight capture: start-to-end at least this share of its smoothed root's path
MOST_HELD = 0.1  # a plain gait's take held on its last pose longer than this share of the window stops
TABLE = "typical_pace.json"
MAX_BYTES = 64 << 10
GAITS = ("walk", "jog", "run")
FLIGHT = ("jog", "run")     # keep their cadence; shorter strides instead
TOLERANCE = 0.03            # a motion within this share of its typical speed is left as it is
FAST_UP_TO = {"jog": "run"}   # a gait asked fast goes at most halfway to the next gait's typical speed
MAX_CHANGE = 1.5            # the most a motion's speed is changed by (either way)
MOVING = 0.2                # m/s: a motion slower than this is not a gait going anywhere: left as it is
SLOW_TAKE = 0.95            # a captured take under this share of its typical speed does not compete


def load_typical_speeds(model_dir) -> dict[str, float]:
    """{gait: typical speed (m/s) on the average body} from ``model_dir/TABLE``; {} without one.
    A damaged table is a ShapeMoveError naming the file."""
    from ..io.limits import read_bounded
    from ..model_files import verify_file

    path = Path(model_dir) / TABLE
    if not path.is_file():
        return {}
    verify_file(path)
    try:
        data = json.loads(read_bounded(path, MAX_BYTES, "typical pace").decode("utf-8"))
        speeds = {str(g): float(row["speed"]) for g, row in data["gaits"].items()}
    except (ValueError, KeyError, TypeError, AttributeError) as e:
        raise ShapeMoveError(f"{path}: not a typical pace table ({e}); write it again with "
                             "python tools/typical_pace.py --data DATA --model MODEL") from None
    if data.get("format") != FORMAT or not all(0.2 < s < 10.0 for s in speeds.values()):
        raise ShapeMoveError(f"{path}: not a typical pace table of format {FORMAT} with speeds in m/s")
    return speeds


def plain_gait(words, slow: bool = False) -> str | None:
    """The one gait of ``GAITS`` the words (``plan.words.Words``) name when they ask nothing else of
    it (module doc: no pace, count, side or manner: "walks proudly" goes at the proud take's pace);
    None otherwise. ``slow``: a slow pace asked of it counts as plain (a slow gait is slowed from
    its typical speed, not from a brisk one's)."""
    gait = lined_gait(words)
    if gait is None:
        return None
    asked = (None if slow and words.pace == "slow" else words.pace, words.count, words.side, words.manner)
    return None if any(a not in (None, False) for a in asked) else gait


def lined_gait(words) -> str | None:
    """The one gait of ``GAITS`` the words ask to go on along a line (``going_gait``, with no course,
    turn, place, second thing or way other than forward asked), at any pace; None otherwise."""
    gait = going_gait(words)   # one gait, no stop, steps, distance or standing
    return gait if gait is not None and along_a_line(words) else None


def along_a_line(words) -> bool:
    """Whether the words (``plan.words.Words``) ask no course, turn, place or second thing, and no
    way other than forward."""
    if any(a not in (None, False) for a in (words.course, words.turn, words.parts)) or words.in_place:
        return False
    return not (words.travel.forward < 0 or words.travel.side or words.travel.sideways)


def leg_length(rest) -> float:
    """Hip to ankle, vertically, of rest joints (24,3)."""
    rest = np.asarray(rest)
    return float(rest[1, 1] - rest[7, 1])


def rest_of(body, betas) -> np.ndarray:
    """(24,3) rest joints of the body ``betas`` (None: the average body)."""
    import torch

    b = torch.zeros(1, body.num_betas) if betas is None else torch.as_tensor(np.asarray(betas, np.float32).reshape(1, -1))
    with torch.no_grad():
        return body.rest_joints(b)[0, :24].numpy()


def leg_ratio(body, betas_from, betas_to) -> float:
    """How much longer the leg of the body ``betas_to`` is than that of ``betas_from``."""
    return leg_length(rest_of(body, betas_to)) / leg_length(rest_of(body, betas_from))


def body_speed(typical: float, body, betas) -> float:
    """``typical`` (m/s on the average body) on the body ``betas``: scaled by its leg's length
    (hip to ankle, rest pose) against the average body's."""
    return typical * leg_ratio(body, None, betas)


def paced_gait(words, course: bool = True) -> str | None:
    """The gait of ``GAITS`` whose typical pace a motion of the words is brought down to: a plain
    gait, one asked slowly (``plain_gait``), or, with ``course``, the gait of a course ("jogs in a
    circle": its gait is made straight, then bent onto the course, ``course_walk.py``) asked no
    faster; None otherwise."""
    gait = plain_gait(words, slow=True)
    if gait is None and course and words is not None and words.course is not None and words.pace != "fast":
        walked = words.course_gait
        gait = walked[1] if walked and walked[1] in GAITS else None
    return gait


def fast_gait(words) -> str | None:
    """The gait of ``FAST_UP_TO`` the words ask fast along a line and nothing else of ("a man jogs
    quickly"); None otherwise."""
    gait = lined_gait(words)
    if gait not in FAST_UP_TO or words.pace != "fast" or any(a not in (None, False) for a in (words.count, words.side)):
        return None
    return gait


def paced_target(words, speeds: dict, course: bool = True) -> tuple[str, float] | None:
    """(gait, speed in m/s on the average body) a motion of the words is brought down to: its plain
    gait's typical speed (``paced_gait``), or, for a gait asked fast (``fast_gait``), halfway from its
    typical speed to the next gait's; None when none applies or the table lacks the gaits."""
    gait = paced_gait(words, course)
    if gait is not None:
        return (gait, speeds[gait]) if gait in speeds else None
    fast = fast_gait(words)
    if fast is None or fast not in speeds or FAST_UP_TO[fast] not in speeds:
        return None
    return fast, halfway(fast, speeds)


def halfway(gait: str, speeds: dict) -> float:
    """Halfway from ``gait``'s typical speed to the next gait's (``FAST_UP_TO``), m/s on the average body."""
    return (speeds[gait] + speeds[FAST_UP_TO[gait]]) / 2


def typical_paced(motion, body, words, speeds: dict, ik_refine_iters: int = 10, course: bool = True):
    """``motion`` brought down to its plain gait's typical speed on its body, a jog asked fast to
    ``paced_target``'s (module doc); the motion itself when the words ask more than a plain gait
    (or a slow or a fast one: ``plain_gait``, ``fast_gait``), the table lacks the gait, or it is no
    more than ``TOLERANCE`` above that speed. A gait asked slowly is
    brought down here before ``slow_steps`` slows it: "jogs slowly" goes slower than "jogs" whichever
    take or sample was chosen (a 2.5 m/s DeepMimic jog slowed by a fifth would outrun a plain jog). So is
    a course's gait, before it is bent onto the course (``paced_gait``; ``course`` False: not)."""
    from ..motion.root_speed import mean_speed
    from .stride_scale import scaled_strides
    from .track import Track, replanted, resample, track_of

    target = paced_target(words, speeds, course)
    if target is None or motion.num_frames < 4 or motion.network_joints is None:
        return motion
    gait, typical = target
    want = body_speed(typical, body, motion.betas)
    speed = mean_speed(motion.joints, motion.fps)
    if speed < MOVING or speed <= want * (1 + TOLERANCE):
        return motion
    share = max(want / speed, 1.0 / MAX_CHANGE)
    track = track_of(motion)
    if gait in FLIGHT:
        return replanted(motion, body, Track(scaled_strides(track.joints, share), track.contacts), ik_refine_iters)
    # a walk played slower: as many of its frames as bring the track's own speed to the share asked
    n = len(track.joints)
    goal = share * mean_speed(track.joints, motion.fps)
    lo, hi = 2, n
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if mean_speed(resample(Track(track.joints[:mid], track.contacts[:mid]), n).joints, motion.fps) < goal:
            lo = mid
        else:
            hi = mid
    return replanted(motion, body, resample(Track(track.joints[:hi], track.contacts[:hi]), n), ik_refine_iters)


def straight(centre) -> bool:
    """Whether a smoothed root path (T,2) goes straight: its start-to-end distance at least
    ``STRAIGHT`` of its length (a turning or circling capture is another task)."""
    c = np.asarray(centre, np.float64)
    along = float(np.linalg.norm(np.diff(c, axis=0), axis=1).sum())
    return along > 0 and float(np.linalg.norm(c[-1] - c[0])) >= STRAIGHT * along


def unplain_take(window, words) -> bool:
    """Whether the captured take ``window`` is not the gait the words ask for: it stops (held on its
    last pose for more than ``MOST_HELD`` of the window: a 1.9 s jog, then standing) where the words
    ask a gait that goes on (``going_gait``: "jogs", "jogs slowly"), or it turns off its line (its
    root's smoothed path is not ``straight``: a jog around a circle) where they ask the plain gait
    (``plain_gait``). Like a slow take, it does not compete."""
    from .track import root_centre

    n = len(window.root) - window.held
    if going_gait(words) is not None and (window.held > MOST_HELD * len(window.root) or n < 2):
        return True
    if plain_gait(words) is None:
        return False
    return not straight(root_centre(np.asarray(window.root, np.float64)[:n, None, :]))


def going_gait(words) -> str | None:
    """The one gait of ``GAITS`` the words name when they ask it to go on (no stop, steps, distance or
    standing: "jogs slowly", "walks forward, waving"); None otherwise."""
    if words is None or len(words.actions) != 1 or words.actions[0] not in GAITS:
        return None
    if words.stop or words.steps is not None or words.distance_m is not None or words.stand_still:
        return None
    return words.actions[0]


def fast_take(window, words, speeds: dict, body) -> bool:
    """Whether the captured take ``window`` of a plain gait of ``FAST_UP_TO`` goes faster than halfway
    from its typical speed to the next gait's, on the performer's body: the next gait's pace
    (DeepMimic's jog, 2.8 m/s with both feet off the floor 36 % of the time, against the data's jogs
    at 1.3-2.0 m/s and 8 %; brought down by shorter strides it still ran). Like a slow take, it does
    not compete, for the plain gait or the gait asked slowly (slowed from a run's pace, "jogs slowly,
    waving" went as fast as "jogs along, waving"); False when the words ask more than that or the
    table lacks the gaits."""
    gait = plain_gait(words, slow=True)
    if gait not in FAST_UP_TO or gait not in speeds or FAST_UP_TO[gait] not in speeds:
        return False
    return take_speed(window) > on_performer(halfway(gait, speeds), window, body)


def slow_take(window, words, speeds: dict, body) -> bool:
    """Whether the captured take ``window`` (``captured_takes.Window``) goes slower than
    ``SLOW_TAKE`` of its plain gait's typical speed on the performer's body (module doc); False when
    the words ask more than a plain gait or the table lacks it."""
    gait = plain_gait(words)
    if gait is None or gait not in speeds:
        return False
    return take_speed(window) < SLOW_TAKE * on_performer(speeds[gait], window, body)


def take_speed(window) -> float:
    """A captured take's (``captured_takes.Window``) speed along its root's path, m/s, over the frames
    it plays before any held on its last pose."""
    return gait_speed(np.asarray(window.features)[: max(1, len(window.features) - window.held)])


def on_performer(speed: float, window, body, betas=None) -> float:
    """A ``speed`` (or a length) on the body ``betas`` (None: the average body) on the performer of the
    take ``window``: scaled by its leg's length against that body's."""
    return speed * leg_length(window.rest) / leg_length(rest_of(body, betas))
