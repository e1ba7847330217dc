"""A prompt's ordered segments: "a person walks forward, then sits down" is two.

    plan = read_plan("after waving, she jogs")       # plan.py, from split_segments here
    [s.text for s in plan.segments]  -> ["she is waving", "she jogs"]
    plan.lengths(6.0)                -> [3.0, 3.0]

Only words that order make segments (``vocabulary.THEN``): "then", "and then", ", then", "after
that", "afterwards", "after which", "next", "finally", "(a minute) later", "eventually",
"subsequently", "followed by", "finishes / ends with", "follows it with", "first ... then", and
"before" / "after" in front of a clause ("after waving, she jogs", "she jogs after waving", "before
sitting down he waves": the wave first; at the start also in front of a noun and its comma, or a
noun and the main clause's subject: "after a bow, ...", "after a long walk she sits down"; "once"
in front of a clause and "having" with its comma are an "after": "once she has waved, she runs off"). Where
an order word cuts, the commas of a list of steps before it cut too ("walks ahead, spins around,
then waves": three; ``vocabulary.LIST_STEP``), but not before a participle ("jogs, waving": two
things at once) nor before a turn (the turn ends its gait). A way alone after an order word goes
on with the verb before it ("runs to the left, then to the right": "runs to the right";
``vocabulary.WAY_ALONE``). "And" cuts beside a change of posture ("gets up and walks away", "walks over and
sits down"; ``vocabulary.POSTURE_CHANGES``), never after a squat's own standing up, and between two
actions one body does not do at once ("runs to the car and jumps in", "walks forward, turns around
and walks back"); two things at once ("jogs and waves": a gait and an arm gesture) are one segment
made by body part (``generation/parts.py``), "jumps and twirls" one action, a turn beside its gait
one segment ("walks and turns left"), and "back and forth", "to and fro", "up and down" are courses.
"After" / "before" cut only before a participle or a pronoun ("runs after the ball" is one thing).
A "before" / "after" clause must name an action and the clause it orders name one or say what
someone does ("jumps and turns before landing" is one; "before crouching down, she glances around"
two: a motion no take is of, then the crouch),
and what follows "then" must say what someone does ("bends the knees, then straightens" is one
squat; ``part_prompts._has_verb``). A stop after "then" is the gait's own ("walks forward, then
stops": one segment that stops, ``vocabulary.STOP``). "Followed by a jump": "a person does
a jump".
A segment without a subject gets the prompt's ("a man walks, then sits" -> "a man sits"); a bare
participle is said as a clause ("waving" -> "she is waving"). Each segment gets an equal share of
the length (``SEGMENT_SECONDS`` each when no length is asked, or what a counted action's
repetitions take: ``plan.counted_seconds``).
"""
from __future__ import annotations

import re

from ..data.actions import action_spans, find_actions
from .part_prompts import LEGS, SUBJECT, _has_verb, _subject, _with_subject, at_once, named_side
from .reader import stop_request
from .vocabulary import (AND, BEFORE_AFTER as MIDDLE, FIRST, LEADING_BEFORE_AFTER as LEADING, LIST_STEP, LOWERED, MID_STOP,
                         PARTICIPLE, POSTURE_CHANGES, RAISES, RISEN_FROM, STOP, THEN, WAY_ALONE)

DEFAULT_SUBJECT = "a person"
SEGMENT_SECONDS = 3.0       # a segment's length when the prompt's length is the model's to choose
MIN_SEGMENT_SECONDS = 0.4   # the shortest segment a timeline takes (``generation.sequence.check_segments``)


def _tidy(piece: str) -> str:
    piece = re.sub(r"\s+", " ", piece).strip(" ,;.:!")
    piece = re.sub(r"\s*,?\s*\band$", "", piece)   # "bows and, after that, walks off"
    return re.sub(r"^(?:and|then|so)\b\s*", "", piece).strip(" ,;.")


def _main_clause_start(t: str) -> int | None:
    """Where a clause opening with "before" / "after" and no comma ends: at the first subject after
    its first words ("before sitting down he waves" -> "he waves"); None when there is none."""
    for w in list(re.finditer(r"\b[a-z]", t))[1:]:
        if SUBJECT.match(t[w.start():]) and re.search(r"\w\s+\w", t[w.start():]):
            return w.start()
    return None


def _both_act(main: str, sub: str) -> bool:
    """Whether a "before" / "after" clause ``sub`` and the clause it orders, ``main``, are two
    motions: ``sub`` names an action of the vocabulary and ``main`` names one too or says what
    someone does ("before crouching down, she glances around": a motion no take is of, then the
    crouch). "Jumps, turning before landing" and "favouring one leg after twisting an ankle" are
    one motion."""
    return bool(find_actions(sub)) and (bool(find_actions(main)) or _has_verb(_tidy(main)))


def _ordered(piece: str) -> list[str]:
    """One piece between "then"s cut at a "before" / "after" clause, in the order it happens."""
    lead = LEADING.match(piece)
    if lead:
        rest = piece[lead.end():]
        comma = rest.find(",")
        cut = comma if comma >= 0 else _main_clause_start(rest)
        if cut is not None and _both_act(rest[cut:], rest[:cut]):
            sub, main = rest[:cut], rest[cut:]
            pair = [main, sub] if lead.group(1) == "before" else [sub, main]   # "after", "once"
            return [p for part in pair for p in _ordered(_tidy(part))]
    mid = MIDDLE.search(piece)
    if mid and mid.start() > 0 and _both_act(piece[:mid.start()], piece[mid.end():]):
        main, sub = piece[:mid.start()], piece[mid.end():]
        pair = [sub, main] if mid.group(1) == "after" else [main, sub]
        return [p for part in pair for p in _ordered(_tidy(part))]
    return [piece]


def _changes_posture(action: str, before: list[str]) -> bool:
    """Whether ``action`` changes the body's posture after actions ``before``: standing up after a
    squat or a bend is that action's own end."""
    return action in POSTURE_CHANGES and not (action == "get up" and any(x in RISEN_FROM for x in before))


def _one_after_other(first: list[str], then: list[str], whole: list[str]) -> bool:
    """Whether the actions ``first`` (before an "and") and ``then`` (after it) follow one another: the
    last of the one and the first of the other are two actions one body does not do at once
    (``part_prompts.at_once``: "jogs and waves" is one segment made by body part), each its own in
    the ``whole`` piece ("jumps and twirls" is one spin jump), the second no turn ("walks and turns
    left": the turn ends the gait) and the first no turn alone before a gait ("turns around and walks
    away": the turn starts the gait; "turns to the right and waves" is two, the turn on the spot);
    a change of posture on either side has its own rule ("squats and stands up" is one squat)."""
    last, nxt = first[-1], then[0]
    if nxt == "turn" or first == ["turn"] and nxt in LEGS or last == nxt or at_once(last, nxt):
        return False
    if last in POSTURE_CHANGES or nxt in POSTURE_CHANGES:   # said by the posture's own rule (``_and_steps``)
        return False
    return last in whole and nxt in whole


def _and_steps(piece: str, before: str = "") -> list[str]:
    """A piece cut at each "and" between two things done one after the other, each side naming its
    own action: a change of posture on one side ("stands up and runs", "walks to the chair and sits
    down"), or two actions one body does not do at once (``_one_after_other``: "runs to the car and
    jumps in", "walks forward, turns around and walks back"), or a turn after a gait that counts its
    steps or a distance ("walks 10 steps and turns left": the steps, then the turn), and, where it
    cuts, at the commas of a
    list of steps before it ("jumps, squats and waves": three); where no "and" cuts, at the commas of a
    list of verbs of actions done one after the other ("runs, jumps and lands on both feet": two);
    the piece itself otherwise. Standing
    up after a squat or a bend (``before``: what precedes the piece) is that action's own end, no
    action of its own: "squats, then stands up and waves" is two, the squat (which stands up again)
    and "waves". A sit and a gesture are done at once ("sits down and waves": waving seated,
    ``part_prompts.at_once``)."""
    whole = find_actions(piece)
    for m in AND.finditer(piece):
        a, b = piece[:m.start()], piece[m.end():]
        first, then = find_actions(a), find_actions(b)
        if not (first and then and _has_verb(b)):
            continue
        if first == ["get up"] and not _changes_posture("get up", find_actions(before)):
            return _and_steps(b, before)   # the squat's own standing up: "squats, then stands up and waves"
        posture = first[0] != then[0] and not at_once(first[-1], then[0]) and \
            (_changes_posture(first[0], find_actions(before)) or _changes_posture(then[0], first))
        counted = then[0] == "turn" and stop_request(a) is not None   # "walks 10 steps and turns left"
        if posture or counted or _one_after_other(first, then, whole):   # an order: the list of steps before it cuts too
            return _list_steps(a) + _and_steps(b, a)
    steps = _list_steps(piece)   # no "and" orders it: a list of verbs of actions ("runs, jumps and lands")
    if len(steps) > 1 and all(_leads_with_action(y) and (_follows(find_actions(x), find_actions(y), whole)
                                                        or _counted_turn(x, y) or _turn_then_counted(x, y))
                              for x, y in zip(steps, steps[1:])):
        return steps
    return [piece]


def _follows(first: list[str], then: list[str], whole: list[str]) -> bool:
    """Whether a step of a list doing ``then`` follows one doing ``first``: one after the other
    (``_one_after_other``), or a change of posture between two actions not done at once ("walks,
    sits down")."""
    if not first or not then:
        return False
    posture = first[0] != then[0] and not at_once(first[-1], then[0]) and \
        (_changes_posture(then[0], first) or _changes_posture(first[-1], []))
    return posture or _one_after_other(first, then, whole)


def _leads_with_action(step: str) -> bool:
    """Whether a step of a list begins with the word of an action ("jumps and lands"), not a part of
    the body doing it ("arms swinging up")."""
    spans = action_spans(step.strip())
    return bool(spans) and spans[0][0] == 0


def _says_something(piece: str) -> bool:
    """Whether a piece holds a word beyond its subject ("then he" and "then 123" do not)."""
    subject = SUBJECT.match(piece)
    return bool(re.search(r"[a-z]{2,}", piece[subject.end():] if subject else piece))


def _as_prompt(piece: str, subject: str) -> str:
    piece = _tidy(FIRST.sub("", piece, count=1) if FIRST.search(piece) else piece)
    if PARTICIPLE.match(piece):
        return f"{subject} is {piece}"
    if re.match(r"(?:a|an|the)\s", piece) and not SUBJECT.match(piece):   # "followed by a jump"
        return f"{subject} does {piece}"
    return _with_subject(piece, subject)


def _gone_on(before: str, way: str) -> str:
    """A way or a side alone after an order word said with the verb of the piece before it: ("a man
    runs to the left", "to the right") -> "a man runs to the right"; ("raises the right hand", "the
    other one") -> "raises the left one"."""
    side = named_side(before)
    if side is not None and re.search(r"\bother\b(?!\s+way)", way):
        way = re.sub(r"\bother\b(?!\s+way)", "left" if side[0] == "right" else "right", way)
    subject = SUBJECT.match(before)
    verb = re.match(r"\s*([a-z'-]+)", before[subject.end():] if subject else before)
    return f"{subject.group(0) if subject else ''} {verb.group(1) if verb else 'walks'} {way}".strip()


def _counted_turn(before: str, step: str) -> bool:
    """Whether ``step`` is a turn alone after a gait that counts its steps or a distance (``before``:
    "walks three steps", "turns left"): the steps, then the turn."""
    return find_actions(step) == ["turn"] and stop_request(before) is not None


def _turn_then_counted(before: str, step: str) -> bool:
    """Whether ``step`` is a gait that counts its steps or a distance after a turn alone in a list
    ("..., turns right, walks 2 metres, ..."): the turn, then the measured walk."""
    return find_actions(before) == ["turn"] and stop_request(step) is not None


def _list_steps(piece: str) -> list[str]:
    """A piece cut at its commas where a verb of an action of its own follows ("she walks ahead, spins
    around" -> two); "jogs, waving" (two things at once) is one, and so is a gait's turn ("walks
    forward, turns around": the turn ends the walk, as a stop does), unless the gait counts its steps
    or a distance ("walks three steps, turns left": the steps, then the turn, as with "and")."""
    out, start = [], 0
    for m in LIST_STEP.finditer(piece):
        step = re.split(r",", piece[m.end():], maxsplit=1)[0]
        before = piece[start:m.start()]
        if (set(find_actions(step)) - {"turn"} or _counted_turn(before, step)) and find_actions(before) and _has_verb(step):
            out.append(before)
            start = m.end()
    return out + [piece[start:]]


def split_segments(prompt: str) -> list[str]:
    """The prompts of ``prompt``'s segments in the order they happen (module doc); one when no word
    orders it, the prompt itself."""
    t = re.sub(r"\s+", " ", str(prompt)).strip().lower()
    t = MID_STOP.sub(r", then \1, then ", t)   # "walks, stops, and waves": the walk's stop, then the wave
    pieces = []
    for p in (_tidy(p) for p in THEN.split(t)):
        subject = SUBJECT.match(p)
        rest = p[subject.end():] if subject else p
        if pieces and p and WAY_ALONE.match(rest):
            pieces.append(_gone_on(pieces[-1], rest))   # "runs to the left, then to the right"
        elif pieces and p and (STOP.match(rest) or not (find_actions(rest) or _has_verb(rest))
                               or LOWERED.match(rest) and set(find_actions(pieces[-1])) & RAISES):
            pieces[-1] = f"{pieces[-1]}, then {p}"   # the gait's own stop, a raise's lowering, or no motion of its own
        else:
            pieces.append(p)
    if len(pieces) > 1:   # a list of steps: "walks ahead, spins around, then waves"
        pieces = [q for p in pieces for q in _list_steps(p)]
    ordered = [q for p in pieces if p for q in _ordered(p)]
    ordered = [q for i, o in enumerate(ordered) for q in _and_steps(o, ordered[i - 1] if i else "")
               if _says_something(_tidy(q))]
    if len(ordered) < 2:
        return [str(prompt).strip()]
    subject = next((_subject(q) for q in ordered if SUBJECT.match(q)), DEFAULT_SUBJECT)
    return [_as_prompt(q, _subject(q) if SUBJECT.match(q) else subject) for q in ordered]
