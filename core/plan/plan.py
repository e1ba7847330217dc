"""The typed plan of a prompt: its ordered segments, each with its share of the length and the
reading of its words (``words.Words``); what the generator acts on.

    plan = read_plan("a person walks forward, then sits down")
    [s.text for s in plan.segments]          -> ["a person walks forward", "a person sits down"]
    plan.segments[0].words.travel.way        -> "forward"
    plan.lengths(6.0)                        -> [3.0, 3.0]
    plan_from_json(plan_json(...))           # an edited plan (``generate --plan PLAN.json``)

The JSON is what ``generate --explain`` prints (``explain.plan_json``); ``plan_from_json`` reads it
back, edited, and says which field is wrong when one is. In a segment's ``understood`` the user
may change, add or remove: ``actions`` (the first is the segment's action: a new one replaces the
action's words in the text the model reads), ``side`` ("left hand"), ``course`` and ``course_way``,
``turn_degrees``, ``travel``, ``in_place``, ``distance_m``, ``steps``, ``stop``, ``stand_still``,
``count``, ``pace``, ``seconds`` (the length its words ask), ``arms_held`` (the raised arms kept
up), ``held_low`` (a squat kept down), ``hands`` (a gesture's hands: "both" or "one"), ``one_foot`` (a hop or jump asked on one foot:
said not to be met), ``again`` (a counted action repeated for the whole length), ``manner`` (how it
is done: a name of
``vocabulary.MANNERS``, "proud"); a segment's ``text`` and ``seconds``
(its length, which wins) too. A field left out asks nothing. The
motion keeps the plan (``Motion.plan``), so a timeline re-decoded for a new body or a strip
regenerated acts on its edited segments again (``generation/timeline_plan.plan_readings``).
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, replace

from ..errors import ShapeMoveError
from .segments import MIN_SEGMENT_SECONDS, SEGMENT_SECONDS, split_segments
from . import vocabulary as V
from .part_prompts import LEGS
from .vocabulary import MANNERS, POSTURE_SECONDS, REPETITION_SECONDS
from .words import Words, read_words

MAX_SEGMENTS = 32          # as a timeline (``generation/sequence.MAX_SEGMENTS``)
MAX_SECONDS = 60.0
MAX_PLAN_BYTES = 256 * 1024


@dataclass(frozen=True)
class Segment:
    text: str                      # the segment's own prompt, with a subject
    share: float                   # its share of the whole length (the shares add up to 1)
    words: Words                   # what its words ask (``words.read_words``, or the user's edit)
    seconds: float | None = None   # its own length, when the user set one (``generate --plan``)


@dataclass(frozen=True)
class Plan:
    prompt: str
    segments: tuple[Segment, ...]
    seconds: float | None = None   # the whole length asked (None: the model's, or the segments' own)

    @property
    def is_sequence(self) -> bool:
        return len(self.segments) > 1

    def lengths(self, total: float | None, course_seconds=None) -> list[float]:
        """Each segment's seconds of a motion ``total`` seconds long (None: the length its words
        ask, "for ten seconds", else ``own_seconds``); a segment's own seconds (an edited plan's)
        win. ``course_seconds(words) -> seconds | None``: the time a segment's course takes to go
        once round, or its distance to be gone and stood (the model's typical pace:
        ``generation.course_shapes.unasked_seconds``)."""
        if all(s.seconds is not None for s in self.segments):
            return [float(s.seconds) for s in self.segments]
        if total is None:   # the words' own length ("for ten seconds"), else the model's
            return [float(s.seconds) if s.seconds is not None else own_seconds(s.words, course_seconds)
                    for s in self.segments]
        return [float(s.seconds) if s.seconds is not None else s.share * float(total) for s in self.segments]


def own_seconds(words: Words, course_seconds=None) -> float:
    """A segment's seconds when no length is set: the length its words ask ("for ten seconds"),
    else the time its course takes to go once round (``course_seconds(words)``, when given and the
    course has a round: "walks a loop around the tree") or its distance to be gone and stood
    ("walks 5 metres, then turns around": at least ``counted_seconds``), else ``counted_seconds``."""
    if words.seconds is not None:
        return float(words.seconds)
    way = words.course is not None or words.distance_m is not None
    once = course_seconds(words) if course_seconds is not None and way else None
    if once is not None and words.course is None:
        return max(float(once), counted_seconds(words))
    return float(once) if once is not None else counted_seconds(words)


def counted_seconds(words: Words) -> float:
    """A segment's seconds when the length is the model's: ``SEGMENT_SECONDS``, or as long as its
    counted repetitions take ("six jumping jacks": 6 x 1.1 s and one more for the start and the end),
    or its change of posture ("lies down": 5.3 s from the first drop to lying still,
    ``vocabulary.POSTURE_SECONDS``; in 3 s a captured lie-down starts on its knees)."""
    if words.count is None:
        return max([SEGMENT_SECONDS] + [POSTURE_SECONDS[a] for a in words.actions if a in POSTURE_SECONDS])
    action, times = words.count
    return max(SEGMENT_SECONDS, (times + 1) * REPETITION_SECONDS.get(action, 0.0))


def read_plan(prompt: str, seconds: float | None = None) -> Plan:
    """The plan of ``prompt``: its ordered segments (``segments.split_segments``), each an equal
    share of the length, each read by ``words.read_words`` and turned back when it returns
    (``returned``)."""
    texts = split_segments(prompt)
    words = returned([read_words(t) for t in texts])
    return Plan(str(prompt), tuple(Segment(t, 1.0 / len(texts), w) for t, w in zip(texts, words)),
                None if seconds is None else float(seconds))


def returned(words: list[Words]) -> list[Words]:
    """Each segment's reading, a gait's return ("walks back", "runs back": ``vocabulary.RETURN``) after a
    segment that does not turn given half a turn ("walks forward, then walks back" comes back; its
    gait turns on its track, ``reader.angle_of``); a return after a turn ("turns around, then walks
    back"), or with a turn or course of its own, as read."""
    out = list(words)
    for i in range(1, len(out)):
        w, before = out[i], out[i - 1]
        gait = any(a in LEGS for a in w.actions)
        if gait and V.RETURN.search(w.text) and w.turn is None and w.course is None and before.turn is None:
            out[i] = replace(w, turn=math.pi)
    return out


def plan_to_json(plan: Plan, course_seconds=None) -> dict:
    """The plan as the JSON ``--explain`` prints (``explain.plan_json`` adds the option notes);
    ``course_seconds`` as ``Plan.lengths``."""
    lengths = plan.lengths(plan.seconds, course_seconds) if plan.is_sequence or plan.seconds is not None or \
        plan.segments[0].seconds is not None or plan.segments[0].words.seconds is not None else [None]
    return {"prompt": plan.prompt, "seconds": plan.seconds,
            "segments": [{"text": s.text, "share": round(s.share, 4),
                          "seconds": None if sec is None else round(sec, 3), "understood": s.words.understood()}
                         for s, sec in zip(plan.segments, lengths)]}


def plan_text(plan: Plan) -> str:
    """The plan as one line of JSON (kept in the motion file, ``Motion.plan``)."""
    return json.dumps(plan_to_json(plan), separators=(",", ":"))


# -- reading an edited plan -----------------------------------------------------------------------
def _bad(where: str, what: str) -> ShapeMoveError:
    return ShapeMoveError(f"plan: {where}: {what}")


def _number(value, where: str, lo: float, hi: float, whole: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise _bad(where, f"must be a number, got {value!r}")
    if whole and value != int(value):
        raise _bad(where, f"must be a whole number, got {value!r}")
    if not lo <= value <= hi:
        raise _bad(where, f"must be between {lo:g} and {hi:g}, got {value!r}")
    return int(value) if whole else float(value)


def _flag(value, where: str) -> bool:
    if not isinstance(value, bool):
        raise _bad(where, f"must be true or false, got {value!r}")
    return value


def _text(value, where: str, limit: int = 500) -> str:
    if not isinstance(value, str) or not value.strip():
        raise _bad(where, f"must be a non-empty text, got {value!r}")
    if len(value) > limit:
        raise _bad(where, f"is longer than {limit} characters")
    return value.strip()


def _choice(value, where: str, options) -> str:
    if value not in options:
        raise _bad(where, f"{value!r} is not one of {', '.join(repr(o) for o in options)}")
    return value


UNDERSTOOD_KEYS = ("actions", "legs", "arms", "course", "course_way", "turn_degrees", "travel", "in_place",
                   "distance_m", "steps", "stop", "stand_still", "count", "pace", "slowly", "seconds", "side",
                   "arms_held", "held_low", "hands", "one_foot", "again", "manner", "unused")


def _swap_action(text: str, old: str | None, new: str) -> str:
    """``text`` with the words of its action ``old`` replaced by ``new``'s own phrase ("a person walks
    forward", walk -> run: "a person runs forward"); the subject and ``new``'s phrase when ``old`` is
    not in it."""
    from ..data.actions import ACTIONS, action_spans, split_words
    from .part_prompts import _subject

    low = split_words(text)
    phrase = ACTIONS[new].phrases[0]
    spans = [sp for sp in action_spans(low) if sp[2] == old]
    if not spans:
        return f"{_subject(low)} {phrase}"
    a, b, _ = spans[0]
    tail = low[b:]
    for said in ACTIONS[old].phrases:   # the old verb's particle ("sits down": "down")
        rest = " ".join(said.split()[1:])
        if rest in ("down", "up", "over", "out", "around") and tail.lstrip().startswith(rest):
            tail = tail.lstrip()[len(rest):]
            tail = tail if not tail or tail[0] in " ,.;" else " " + tail
            break
    low = low[:b] + tail
    return (low[:a] + phrase.split()[0] + low[b:]) if " " not in phrase.strip() else (low[:a] + phrase + low[b:])


def _drop_action(text: str, action: str) -> str:
    """``text`` without the words of its ``action`` and the "and" that joined them ("a woman stands
    up and waves", get up -> "a woman waves")."""
    from ..data.actions import action_spans, split_words

    low = split_words(text)
    for a, b, name in action_spans(low):
        if name == action:
            left, right = low[:a].rstrip(), low[b:].lstrip()
            right = re.sub(r"^(?:and|,|then|while)\s+", "", right)
            left = re.sub(r"(?:\s+and|,)$", "", left) if not right or right[0] in ",.;" else left
            low = f"{left} {right}".strip()
            break
    return low


def _edited_words(seg: dict, where: str, text: str) -> tuple[str, Words]:
    """(the text the model reads, the reading) of one edited segment (module doc)."""
    from ..data.actions import ACTIONS, find_actions
    from .part_prompts import PartPlan, named_side, plan_parts
    from .reader import TRAVEL_WAYS
    from .vocabulary import COUNTED, COURSE_KINDS, MAX_METRES, MAX_STEPS, MAX_COUNT

    said = seg.get("understood", {})
    if not isinstance(said, dict):
        raise _bad(f"{where}.understood", f"must be an object, got {type(said).__name__}")
    unknown = [k for k in said if k not in UNDERSTOOD_KEYS]
    if unknown:
        raise _bad(f"{where}.understood.{unknown[0]}", f"is no field of a plan (fields: {', '.join(UNDERSTOOD_KEYS)})")
    read = read_words(text)
    actions = said.get("actions", [])
    if not isinstance(actions, list) or not all(isinstance(a, str) for a in actions):
        raise _bad(f"{where}.understood.actions", f"must be a list of action names, got {actions!r}")
    for i, a in enumerate(actions):
        if a not in ACTIONS:
            raise _bad(f"{where}.understood.actions[{i}]", f"{a!r} is no action the model knows "
                       f"(e.g. {', '.join(sorted(ACTIONS)[:8])}, ...: docs/prompts.md)")
    if actions and actions[0] not in read.actions:   # a new action: its words replace the old one's
        text = _swap_action(text, read.actions[0] if read.actions else None, actions[0])
        read = read_words(text)
    reworded = False
    if actions:   # actions taken out lose their words, actions put in are said
        before = text
        for gone in [a for a in read.actions if a not in actions]:
            text = _drop_action(text, gone)
        text = " and ".join([text] + [ACTIONS[a].phrases[0] for a in actions[1:] if a not in find_actions(text)])
        read, reworded = read_words(text), text != before
        if read.actions and set(read.actions) != set(actions):
            raise _bad(f"{where}.understood.actions", f"{actions!r} cannot be said in one segment (its text reads "
                       f"{list(read.actions)!r}: {text!r}); edit the segment's text")
    parts = read.parts
    if "legs" in said or "arms" in said:
        legs = _text(said.get("legs"), f"{where}.understood.legs")
        arms = _text(said.get("arms"), f"{where}.understood.arms")
        found = plan_parts(f"{legs} while {arms}")
        if found is None:
            raise _bad(f"{where}.understood.legs", f"{legs!r} and {arms!r} are not a gait and a gesture")
        side = named_side(arms)
        parts = PartPlan(legs, arms, found.legs_action, found.arms_action,
                         side if side is not None and side[1] == "hand" else None)
    elif not reworded:   # the printed plan names them: taken out, nothing is made by part
        parts = None
    side = None
    if "side" in said:
        bits = str(said["side"]).split()
        if len(bits) != 2 or bits[0] not in ("left", "right") or bits[1] not in ("hand", "foot"):
            raise _bad(f"{where}.understood.side", f"must be 'left hand', 'right hand', 'left foot' or 'right foot', "
                       f"got {said['side']!r}")
        side = (bits[0], bits[1])
    course = None if said.get("course") is None else _choice(said["course"], f"{where}.understood.course", COURSE_KINDS)
    way = _choice(said.get("course_way", "left"), f"{where}.understood.course_way", ("left", "right"))
    turn = None if said.get("turn_degrees") is None else math.radians(
        _number(said["turn_degrees"], f"{where}.understood.turn_degrees", -1080, 1080))
    travel = TRAVEL_WAYS[_choice(said.get("travel"), f"{where}.understood.travel", tuple(TRAVEL_WAYS))]
    in_place = _flag(said.get("in_place", False), f"{where}.understood.in_place")
    metres = None if said.get("distance_m") is None else _number(said["distance_m"], f"{where}.understood.distance_m",
                                                                 0.1, MAX_METRES)
    steps = None if said.get("steps") is None else _number(said["steps"], f"{where}.understood.steps", 1, MAX_STEPS,
                                                           whole=True)
    stop = _flag(said.get("stop", metres is not None or steps is not None), f"{where}.understood.stop")
    if (metres is not None or steps is not None) and not stop:
        raise _bad(f"{where}.understood.stop", "a distance or a count of steps stops there: stop must be true")
    stand = _flag(said.get("stand_still", False), f"{where}.understood.stand_still")
    hands = None if said.get("hands") is None else _choice(said["hands"], f"{where}.understood.hands", ("both", "one"))
    held = _flag(said.get("arms_held", False), f"{where}.understood.arms_held")
    low = _flag(said.get("held_low", False), f"{where}.understood.held_low")
    one_foot = _flag(said.get("one_foot", False), f"{where}.understood.one_foot")
    again = _flag(said.get("again", False), f"{where}.understood.again")
    count = None
    if said.get("count") is not None:
        n = _number(said["count"], f"{where}.understood.count", 1, MAX_COUNT, whole=True)
        countable = [a for a in (actions or read.actions) if a in COUNTED]
        if not countable:
            raise _bad(f"{where}.understood.count", f"counts jumps, hops, squats or kicks ({', '.join(COUNTED)}); "
                       "the segment names none")
        count = (countable[0], n)
    pace = None if said.get("pace") is None else _choice(said["pace"], f"{where}.understood.pace", ("fast", "slow"))
    slowly = _flag(said.get("slowly", False), f"{where}.understood.slowly") and pace is None
    length = None if said.get("seconds") is None else _number(said["seconds"], f"{where}.understood.seconds",
                                                              MIN_SEGMENT_SECONDS, MAX_SECONDS)
    manner = None if said.get("manner") is None else _choice(said["manner"], f"{where}.understood.manner", tuple(MANNERS))
    gait_text = read.gait_text if read.stop else (text if stop else None)
    flight = pace == "slow" and any(a in ("jog", "run", "sprint") for a in (actions or read.actions))
    return text, replace(read, parts=parts, side=None if parts is not None else side, course=course,
                         course_right=way == "right", turn=turn, travel=replace(travel, in_place=in_place),
                         in_place=in_place and any(a in LEGS for a in (actions or read.actions)),   # a gait's strides
                         stop=stop, steps=steps, distance_m=metres, gait_text=gait_text,
                         stand_still=stand and not stop, count=count, pace=pace, slow_flight=flight, slowly=slowly,
                         seconds=length, hands=hands, arms_held=held, held_low=low, one_foot=one_foot, again=again,
                         manner=manner)


def plan_from_json(data, seconds: float | None = None) -> Plan:
    """The plan of an edited JSON (``--explain``'s form; a dict or its text), checked field by field:
    a ShapeMoveError names the field that is wrong. ``seconds``: the command's ``--seconds``, which
    the plan's own ``seconds`` gives way to."""
    if isinstance(data, (str, bytes)):
        if len(data) > MAX_PLAN_BYTES:
            raise ShapeMoveError(f"plan: larger than {MAX_PLAN_BYTES // 1024} KB")
        try:
            data = json.loads(data)
        except ValueError as exc:
            raise ShapeMoveError(f"plan: not JSON ({exc})") from None
    if not isinstance(data, dict):
        raise _bad("the plan", f"must be a JSON object, got {type(data).__name__}")
    segs = data.get("segments")
    if not isinstance(segs, list) or not 1 <= len(segs) <= MAX_SEGMENTS:
        raise _bad("segments", f"must be a list of 1 to {MAX_SEGMENTS} segments")
    total = data.get("seconds", seconds)
    total = None if total is None else _number(total, "seconds", MIN_SEGMENT_SECONDS, MAX_SECONDS * MAX_SEGMENTS)
    out = []
    for i, seg in enumerate(segs):
        where = f"segments[{i}]"
        if not isinstance(seg, dict):
            raise _bad(where, f"must be an object, got {type(seg).__name__}")
        text = _text(seg.get("text"), f"{where}.text")
        sec = None if seg.get("seconds") is None else _number(seg["seconds"], f"{where}.seconds",
                                                              MIN_SEGMENT_SECONDS, MAX_SECONDS)
        text, words = _edited_words(seg, where, text)
        out.append(Segment(text, 1.0 / len(segs), words, sec))
    prompt = data.get("prompt")
    prompt = _text(prompt, "prompt", 2000) if prompt is not None else ", then ".join(s.text for s in out)
    if len(out) == 1 and total is None and out[0].seconds is not None:
        total = out[0].seconds
    return Plan(prompt, tuple(out), total)
