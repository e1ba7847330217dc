"""The one reader of a prompt's words: the vocabulary (``vocabulary.py``) matched against a text,
each class read once into a typed reading (``words.py`` assembles them: ``read_words``).

    stop_request("a man takes three steps forward and stops")   # ("a man takes three steps forward", 3)
    asked_distance("walks 3 metres")                             # 3.0
    angle_of("a person turns around to the right")               # -pi (radians, + = left)
    course_named("jogs in a figure eight")                       # "walk in a figure eight"
    travel_of("walks backwards")                                 # Travel(forward=-1)

What each reading does to the motion is said where it is done (``generation/stop_words.py``,
``course_walk.py``, ``turn_words.py``, ``travel_words.py``, ``count_words.py``, ``pace_words.py``,
``on_the_spot.py``).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np

from ..data.actions import action_spans, find_actions, specific
from ..data.compose_parts import ARMS_ACTIONS, LEGS_ACTIONS
from . import vocabulary as V
from .part_prompts import LEGS, named_side

STEPPING = LEGS - {"jog", "run", "sprint"}   # gaits without a flight phase
MAX_TURNS = 5   # "spins ten times": at most this many


# -- count ------------------------------------------------------------------------------------
def number_of(word: str) -> int:
    """A count said in digits or words: "3", "three", "a couple of", "twice" (``vocabulary.NUMBERS``,
    ``vocabulary.TIMES``)."""
    word = word.lower()
    return int(word) if word.isdigit() else {**V.NUMBERS, **V.TIMES}[word]


def asked_count(prompt: str) -> tuple[str, int] | None:
    """(the countable action named, how many times it is asked): "a man jumps forward twice" ->
    ("jump forward", 2); None when the words name no countable action (``vocabulary.COUNTED``), no
    count, or a count beyond ``MAX_COUNT``."""
    named = [sp[2] for sp in action_spans(prompt) if sp[2] in V.COUNTED]
    m = V.COUNT_TIMES.search(prompt)
    if not named or m is None:
        return None
    n = number_of(m.group(1) or m.group(2))
    return (named[0], n) if 1 <= n <= V.MAX_COUNT else None


# -- pace -------------------------------------------------------------------------------------
def _gaits(prompt: str) -> set:
    return {sp[2] for sp in action_spans(prompt) if sp[2] in LEGS}


def asks_fast(prompt: str) -> bool:
    """Whether the prompt asks a gait to go fast (and names no slow pace beside it)."""
    return bool(V.FAST.search(prompt)) and not V.SLOW.search(prompt) and bool(_gaits(prompt))


def _slow_gaits(prompt: str) -> set:
    """The gaits the prompt asks to go slowly (a slow pace named, no fast one); empty otherwise."""
    return _gaits(prompt) if V.SLOW.search(prompt) and not V.FAST.search(prompt) else set()


def asks_slow_steps(prompt: str) -> bool:
    """Whether the prompt asks a stepping gait (and no other gait) to go slowly, naming no fast pace."""
    gaits = _slow_gaits(prompt)
    return bool(gaits) and gaits <= STEPPING


def asks_slow_flight(prompt: str) -> bool:
    """Whether the prompt asks a gait with a flight phase (a jog, a run) to go slowly, naming no fast pace."""
    gaits = _slow_gaits(prompt)
    return bool(gaits) and not gaits <= STEPPING


def asks_slow_action(prompt: str) -> bool:
    """Whether the prompt asks an action that is no gait to be done slowly ("an old man sits down
    slowly", "she waves slowly"): a slow pace named, no fast one, no gait and no travel ("backs up
    slowly" steps), an action named."""
    return bool(V.SLOW.search(prompt)) and not V.FAST.search(prompt) and not _gaits(prompt) and \
        not travel_of(prompt).named and bool(action_spans(prompt))


# -- stop, steps, distance, standing ----------------------------------------------------------
def manner_of(text: str) -> str | None:
    """The manner ``text`` says an action is done in (``vocabulary.MANNERS``, the first of its
    order found), or None: a prompt's ("walks proudly": "proud") or a caption's."""
    low = str(text).lower()
    return next((k for k, rx in V.MANNER_PATTERNS.items() if rx.search(low)), None)


def stop_request(text: str) -> tuple[str, int | None] | None:
    """(the prompt without its stop clause or distance, the steps it counts or None) when ``text``
    asks a gait to stop, counts the steps of a gait and asks nothing else ("takes three steps
    forward": the whole prompt, 3), or gives a gait a distance ("walks 3 metres forward": "walks
    forward", None; ``asked_distance`` says how far); None otherwise."""
    t = str(text)
    low = t.lower()
    if V.NOT_STOPPING.search(low):
        return None
    match = V.STOP.search(low)
    if match is None:
        counted = V.STEPS_ALONE.search(low)
        others = set(find_actions(low)) - V.GAITS
        if counted is not None and not others:
            gait = t.strip().rstrip(".")
        elif counted is None and asked_distance(low) is not None and not others - set(ARMS_ACTIONS):
            gait = t.strip().rstrip(".")   # "walks 3 metres forward (waving)": both parts stop there
        else:
            return None   # no count or distance, or another action beside them ("takes two steps and spins")
    else:
        gait = t[:match.start()].strip().rstrip(",")
        counted = V.STEPS.search(gait.lower())
        if not gait or (counted is None and not set(find_actions(gait.lower())) & V.GAITS):
            return None   # "a person stops", "she waves and stops": no gait to stop
    gait = re.sub(r"\s+([,.;])", r"\1", V.SPOKEN_DISTANCE.sub("", gait)).strip() or gait   # the cut goes that far
    steps = None
    if counted is not None:
        steps = number_of(counted.group(1) or counted.group(2))
        steps = steps if 1 <= steps <= V.MAX_STEPS else None
    return gait, steps


def asked_distance(text: str) -> float | None:
    """Metres a gait is asked to go ("walks 3 metres", "ten feet", "2.5 m"), when the words name a
    gait and a distance of at most ``MAX_METRES``; else None."""
    low = str(text).lower()
    m = V.DISTANCE.search(low)
    if m is None or not set(find_actions(low)) & V.GAITS:
        return None
    n = float(m.group(1)) if m.group(1)[0].isdigit() else V.NUMBERS[m.group(1)]
    metres = n * V.UNITS[m.group(2)]
    return metres if 0 < metres <= V.MAX_METRES else None


def asked_seconds(text: str) -> float | None:
    """Seconds the words ask the motion to last ("for ten seconds", "for 2.5 s", "for half a minute",
    "a 10-second jog"), brought within ``MIN_SECONDS`` .. ``MAX_SECONDS`` ("for two minutes": 60 s,
    the most a motion lasts); None when they ask none."""
    m = V.DURATION.search(str(text).lower())
    if m is None:
        return None
    if m.group(5):   # "a 10-second jog"
        n, unit = m.group(5), m.group(6)
    else:
        n, unit = ("0.5" if m.group(1) else m.group(2) or m.group(3)), m.group(4)
    seconds = (float(n) if n[0].isdigit() else float(V.NUMBERS[n])) * V.TIME_UNITS[unit]
    return float(min(max(seconds, V.MIN_SECONDS), V.MAX_SECONDS))


def asks_stand_still(text: str) -> bool:
    """Whether a prompt only asks the body to stand still ("a person stands still", "she waits",
    "he pauses"): a still word and no action (a timeline's segment of standing)."""
    t = str(text).lower()
    return bool(V.STILL.search(t)) and not find_actions(t) and stop_request(t) is None and not V.NOT_STOPPING.search(t)


# -- courses ----------------------------------------------------------------------------------
def course_named(text: str) -> str | None:
    """The course the words name (``EIGHT`` before ``CIRCLE``: "a figure eight" is not a circle;
    not the circles the arms make: "walks forward rotating the arms in circles"; back and forth and a
    zigzag only with a gait to walk it, or as the verb: "sways back and forth" names none; a gait
    to one side, ``ASIDE_COURSE``: "runs to the left", not a sidestep or a walk backward; a square
    with a gait or a verb of going: "walks in a square", "goes around a small square"), else None."""
    acts = find_actions(text)
    if V.EIGHT in acts or (V.CIRCLE in acts and not V.ARM_CIRCLES.search(str(text))):
        return V.EIGHT if V.EIGHT in acts else V.CIRCLE
    gait = any(a in LEGS_ACTIONS for a in acts) or V.COURSE_VERB.search(str(text)) is not None
    if V.SQUARE.search(str(text)) and (gait or V.GOING.search(str(text))):
        return V.SQUARE_COURSE   # "walks in a square", "goes around a small square"
    for name, words in ((V.BACK_AND_FORTH_COURSE, V.BACK_AND_FORTH), (V.ZIGZAG_COURSE, V.ZIGZAG),
                        (V.DIAGONAL_COURSE, V.DIAGONAL)):
        if gait and words.search(str(text)):
            return name
    if any(a in LEGS_ACTIONS and a not in ("sidestep", "walk backward") for a in acts) and V.ASIDE.search(str(text)):
        return V.ASIDE_COURSE   # "runs to the left"
    return None


def _walk_verb(m: re.Match) -> str:
    """"paces" -> "walks", "pacing" / "zigzagging" -> "walking", "zigzagged" -> "walked"."""
    word = m.group(0).lower()
    return "walking" if word.endswith("ing") else "walked" if word.endswith("ed") else "walks"


def straight_gait(text: str) -> tuple[str, str] | None:
    """(the words without the course they name and its way round, the gait left in them) --
    "someone jogs in a figure eight clockwise, waving" -> ("someone jogs, waving", "jog"), "a man
    paces back and forth" -> ("a man walks", "walk") -- or None when the words name no course
    (``course_named``). A circle, an eight or a square whose words name no gait is walked ("a man goes
    around in a circle", "she circles the room" -> ("a man walks", "walk"), ("she walks", "walk"))."""
    text = str(text)
    course = course_named(text)
    if course is None:
        return None
    straight = V.COURSE_VERB.sub(_walk_verb, V.COURSE_WORDS.sub("", text))
    straight = re.sub(r"\s+([,.;])", r"\1", V.COURSE_WAY.sub("", straight)).strip()
    gaits = [a for a in find_actions(straight) if a in LEGS_ACTIONS and a not in V.COURSE_ACTIONS]
    if gaits:
        return straight, gaits[0]
    if course in V.COURSE_ACTIONS or course == V.SQUARE_COURSE:
        subject = V.SUBJECT.match(straight.lower())
        return f"{subject.group(0) if subject else 'a person'} walks", "walk"
    return None


def walked_straight(text: str) -> str:
    """The words a course's gait is sampled from (``straight_gait``'s), else ``text`` itself."""
    gait = straight_gait(text)
    return gait[0] if gait else text


def turns_right(text: str) -> bool:
    """Clockwise seen from above: "clockwise", "to the right" (not "counter-clockwise")."""
    t = str(text).lower()
    return bool(V.CLOCKWISE.search(V.COUNTER_CLOCKWISE.sub(" ", t)))


# -- turns ------------------------------------------------------------------------------------
def angle_of(text: str) -> float | None:
    """The yaw (radians, + = left) a prompt of one turn or spin asks the body to turn, alone or, a
    turn, beside one gait ("walks forward and turns around", "turns left and jogs on"); None when the
    prompt asks for something else too, turns a part or a thing, or names no amount."""
    t = " " + str(text).lower() + " "
    acts = set(specific(find_actions(t)))
    gaits = acts & LEGS
    if len(gaits) == 1 and "turn" in acts:   # a gait that turns: the turn is given back on its track
        acts -= gaits
    if not acts or not acts <= {"turn", "spin"} or V.TURN_NOT_BODY.search(t) or V.TURN_NEGATED.search(t):
        return None
    if V.TURN_WHOLE.search(t) or "spin" in acts:
        a = 2 * np.pi
    elif V.TURN_HALF.search(t):
        a = np.pi
    elif V.TURN_QUARTER.search(t):
        a = np.pi / 2
    else:
        return None
    times = V.TURN_TIMES.search(t)
    if times:   # "spins around three times", "four full turns"
        a *= max(1, min(number_of(times.group(1) or times.group(2)), MAX_TURNS))
    elif V.TURN_TWICE.search(t):
        a *= 2
    right = bool(V.TURN_RIGHT.search(V.COUNTER_CLOCKWISE.sub(" ", t)))
    return float(-a if right else a)


# -- travel -----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Travel:
    """Which way the words send the body: ``forward`` +1 / -1 (backward) / 0, ``side`` +1 (left) /
    -1 (right) / 0, ``sideways`` (either side, more than forward), ``in_place``."""
    forward: int = 0
    side: int = 0
    sideways: bool = False
    in_place: bool = False

    @property
    def named(self) -> bool:
        return bool(self.forward or self.side or self.sideways or self.in_place)

    @property
    def way(self) -> str | None:
        """"forward", "backward", "left", "right", "sideways" or None, as the plan says it."""
        return ({1: "forward", -1: "backward"}.get(self.forward) or {1: "left", -1: "right"}.get(self.side)
                or ("sideways" if self.sideways else None))


TRAVEL_WAYS = {None: Travel(), "forward": Travel(forward=1), "backward": Travel(forward=-1), "left": Travel(side=1),
               "right": Travel(side=-1), "sideways": Travel(sideways=True)}


def travel_of(prompt: str) -> Travel:
    """The travel ``prompt`` names (nothing for a prompt that names none or contradicts itself); a
    turn or a spin alone, no way named, is done on the spot ("a man turns right" walked 2.8-3.1 m in
    3 s on the samples' walks)."""
    fw, bw = bool(V.FORWARD.search(prompt)), bool(V.BACKWARD.search(prompt))
    sides = {m.group(1).lower() for m in V.TRAVEL_SIDE.finditer(prompt)}
    way = Travel(forward=(fw and not bw) - (bw and not fw), side=int(sides == {"left"}) - int(sides == {"right"}),
                 sideways=bool(V.SIDEWAYS.search(prompt)) and not sides,
                 in_place=bool(V.IN_PLACE.search(prompt) or V.JUMP_IN_PLACE.search(prompt)))
    acts = set(specific(find_actions(prompt)))
    if acts and acts <= {"turn", "spin"} and way == Travel():
        return replace(way, in_place=True)   # turning on the spot
    return way


def asks_on_the_spot(prompt: str) -> bool:
    """Whether the prompt keeps a gait in place ("jogs in place", "marches on the spot")."""
    return travel_of(prompt).in_place and any(sp[2] in LEGS for sp in action_spans(prompt))


def hands_asked(prompt: str) -> str | None:
    """"both" when the words ask a gesture of both hands or arms ("waves with both hands", "raises her
    hands"), "one" when of one ("raises a hand", "lifts one hand high", "waves with his left hand"),
    None when they say neither ("waves") or both ways."""
    t = str(prompt).lower()
    side = named_side(t)   # a named hand is one hand; a named foot says nothing of the hands
    both, one = bool(V.BOTH_HANDS.search(t)), bool(V.ONE_HAND.search(t)) or side is not None and side[1] == "hand"
    return "both" if both and not one else "one" if one and not both else None


def again(prompt: str) -> bool:
    """Whether the words ask a counted action (``vocabulary.COUNTED``) again and again without a
    number ("jumps up and down", "squats repeatedly", "keeps kicking"), or give an action a length
    keeps going a length ("shadowboxes for ten seconds", "jumps for 5 seconds": ``vocabulary.KEPT_UP``)."""
    t = str(prompt).lower()
    if asked_count(t) is not None:
        return False
    acts = [sp[2] for sp in action_spans(t)]
    return bool(V.AGAIN.search(t)) and any(a in V.COUNTED for a in acts) or \
        asked_seconds(t) is not None and any(a in V.KEPT_UP for a in acts)


def one_foot(prompt: str) -> bool:
    """Whether the words ask a hop or a jump on one foot ("hops on one foot", "a one-legged hop")."""
    t = str(prompt).lower()
    return bool(V.ONE_FOOT.search(t)) and bool(V.ONE_FOOT_ACTIONS & set(find_actions(t)))


def arms_held(prompt: str) -> bool:
    """Whether the words keep the arms raised ("with both arms raised", "keeps his hand up")."""
    return bool(V.ARMS_HELD.search(str(prompt).lower()))


def held_low(prompt: str) -> bool:
    """Whether the words keep a squat down ("squats and holds it", "crouches and stays there")."""
    t = str(prompt).lower()
    return bool(V.HELD_LOW.search(t)) and bool(V.HELD_LOW_ACTIONS & set(find_actions(t)))


def gestures_only(prompt: str) -> bool:
    """Whether the words name actions and all of them are arms actions ("he waves")."""
    found = set(find_actions(str(prompt).lower()))
    return bool(found) and found <= set(ARMS_ACTIONS)


# -- the body's words -------------------------------------------------------------------------
def without_numbers(prompt: str) -> str:
    """The prompt without its numbers and their units ("walks 10 m in 5 seconds"): what is left may
    describe the body ("an old man"), the numbers describe the motion."""
    return V.NUMBER.sub(" ", str(prompt).lower())


# -- words no reader took ---------------------------------------------------------------------
_TAKEN = (V.COUNT_TIMES, V.FAST, V.SLOW, V.STOP, V.STEPS, V.STEPS_ALONE, V.STILL, V.SPOKEN_DISTANCE, V.CLOCKWISE,
          V.COUNTER_CLOCKWISE, V.BACK_AND_FORTH, V.ZIGZAG, V.DIAGONAL, V.SQUARE, V.COURSE_WORDS, V.COURSE_WAY, V.TURN_WHOLE,
          V.TURN_HALF, V.TURN_QUARTER, V.FORWARD, V.BACKWARD, V.IN_PLACE, V.TRAVEL_SIDE, V.SIDEWAYS, V.SIDE,
          V.DIRECTION, V.SUBJECT, V.TURN_TWICE, V.TURN_TIMES, V.ARMS_HELD, V.HELD_LOW, V.BOTH_HANDS, V.ONE_HAND, V.DURATION, V.ASIDE,
          V.CONNECTOR, V.THEN, V.MANNER, V.ONE_FOOT, V.JUMP_IN_PLACE, V.AGAIN)


def unused_words(text: str, body_words=(), idle=()) -> list[str]:
    """The words of ``text`` that no word class took: not an action, a subject, a body word
    (``body_words``), a small word or any class of the vocabulary ("impatiently" in "a man paces
    impatiently"); ``idle``: classes whose words were said but not acted on (a pace without a gait:
    "sits down slowly"). The model still reads them with the rest of the prompt."""
    from ..data.actions import split_words

    t = split_words(text)
    taken = np.zeros(len(t), bool)
    for s, e, _ in action_spans(t):
        taken[s:e] = True
    for rx in (rx for rx in _TAKEN if rx not in idle):
        for m in rx.finditer(t):
            taken[m.start():m.end()] = True
    body = {str(w).lower() for w in body_words}
    out = []
    for m in V.WORD.finditer(t):
        w = m.group(0).strip("'-")
        if (taken[m.start():m.end()].any() or w in V.SMALL_WORDS or w in body or w in V.NUMBERS or w in V.TIMES
                or len(w) < 2):
            continue
        out.append(w)
    return list(dict.fromkeys(out))
