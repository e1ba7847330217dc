"""What a prompt asks of each body part: two things at once, and a named side.

    plan = plan_parts("a woman jogs along, waving her left hand")
    plan.legs_prompt   -> "a woman jogs along"
    plan.arms_prompt   -> "a person waving her left hand"
    plan.arms_side     -> ("left", "hand")
    named_side("kick with your right foot")  -> ("right", "foot")

Actions are found by the dataset's own action patterns (``data/actions.py``: one vocabulary for
captions, labels and prompts). A prompt is **two things at once** when it names a locomotion
(``LEGS``: walk, jog, run, march, sneak, limp, sidestep, walk backward, in a circle, ...), a sit
(``SEATED``: "sits down and waves" waves seated, where as two segments the body sat, then stood up
again to wave) or an action of the legs that leaves the arms free (``ARMS_FREE``: hops, jumps,
squats; "a child hops while waving" hopped and dropped the wave) and an arm gesture (``ARMS``: wave,
punch, throw, raise a hand, beckon, reach up, arm circles, ...) and no order between them ("then",
"after", "before": a sequence is the timeline's job, ``generation/sequence.py``). The text is cut between the two at the connector that joins them (",", "while",
"as", "and", ...; "with" only where no other joins them: "waves with his right hand while walking"
is cut at "while"; else where the second action starts); each clause becomes its own prompt, the
one without a subject getting "a person".

A **named side** is "left" or "right" with a body part ("left hand", "his right leg", "the left
one"...) or with an action of one part ("kicks left" is a foot, "punches with the right" a hand).
"Turns left", "to the right", "walks left" name a direction, not a side, and are not read.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from ..data.actions import action_spans, split_words
from ..data.compose_parts import ARMS_ACTIONS, LEGS_ACTIONS
from .vocabulary import CONNECTOR, DIRECTION, FOOT_WORDS, HAND_WORDS, ORDER_WORDS, SIDE, SUBJECT

LEGS = frozenset(LEGS_ACTIONS) | {"sprint", "walk in a figure eight"}   # not "zombie walk": its arms are the action
SEATED = frozenset({"sit"})      # a posture the arms' gesture is done in, as a gait's legs carry it
ARMS_FREE = frozenset({"hop", "jump", "jump forward", "squat"})   # done by the legs, the arms free for a gesture
BODY = LEGS | SEATED | ARMS_FREE  # what the legs part of two things at once may be
ARMS = frozenset(ARMS_ACTIONS)
FOOT_ACTIONS = frozenset({"kick", "spin kick", "kick ball", "hop"})


def at_once(first: str, second: str) -> bool:
    """Whether one body does the two actions joined by "and" at once, by part: a locomotion or a sit
    and an arm gesture (``ARMS``), either way round ("jogs and waves", "sits down and waves"); any
    other two follow one another ("jumps and waves", "she jumps, squats and waves": a hop, a jump or
    a squat carries a gesture only where the words join them so, "hops while waving")."""
    legs = LEGS | SEATED
    return (first in legs and second in ARMS) or (first in ARMS and second in legs)


@dataclass(frozen=True)
class PartPlan:
    legs_prompt: str
    arms_prompt: str
    legs_action: str
    arms_action: str
    arms_side: tuple[str, str] | None   # ("left" | "right", "hand"), when the arms clause names a side


def _part_of(word: str | None) -> str | None:
    if not word:
        return None
    w = word.lower()
    if re.fullmatch(HAND_WORDS, w) or w.startswith(("hand", "arm")):
        return "hand"
    if re.fullmatch(FOOT_WORDS, w) or w.startswith(("foot", "leg")):
        return "foot"
    return None


def named_side(text: str) -> tuple[str, str] | None:
    """("left" | "right", "hand" | "foot") when the text names one side of the body, else None
    (no side, both sides, or only a direction such as "turns left")."""
    t = DIRECTION.sub(" ", split_words(text))
    found = set()
    for m in SIDE.finditer(t):
        word = m.group(2) or re.sub(r"^(left|right)[-\s]+", "", m.group(0)).strip() or None
        part = _part_of(word)
        if part is None:  # "the left one", "with the right": the part the action moves
            acts = [a for _, _, a in action_spans(t)]
            if any(a in FOOT_ACTIONS for a in acts):
                part = "foot"
            elif any(a in ARMS or a in ("punch", "slash") for a in acts):
                part = "hand"
        if part is not None:
            found.add((m.group(1), part))
    sides = {s for s, _ in found}
    if len(sides) != 1:
        return None
    parts = {p for _, p in found}
    return (sides.pop(), parts.pop()) if len(parts) == 1 else None


def _tidy(clause: str) -> str:
    c = CONNECTOR.sub(lambda m: m.group(0) if m.group(0).isalpha() else " ", clause)
    c = re.sub(r"^\W*(?:(?:while|whilst|as|and|with|at the same time|all the while|meanwhile|simultaneously)\b\W*)+",
               "", c.strip())
    c = re.sub(r"\W*\b(?:at the same time|simultaneously|meanwhile)\W*$", "", c)
    return re.sub(r"\s+", " ", c).strip(" ,.;")


def _with_subject(clause: str, subject: str = "a person") -> str:
    """``clause`` with a subject: its own ("a man", "she", or any noun a verb follows: "a coach runs
    ahead"), else ``subject``."""
    return clause if SUBJECT.match(clause) or SUBJECT_VERB.match(clause) else f"{subject} {clause}"


def _part_action(clause: str, part: frozenset) -> str | None:
    """The action of ``part`` (LEGS or ARMS) a clause names: the longest matching span ("walks
    around in a circle" is a circle, not a walk), None when it names none."""
    spans = [sp for sp in action_spans(clause) if sp[2] in part]
    return max(spans, key=lambda sp: (sp[1] - sp[0], -sp[0]))[2] if spans else None


def _plan(legs_prompt: str, arms_prompt: str, legs_action: str, arms_action: str) -> PartPlan:
    """The plan, with the side the arms prompt names when it names a hand."""
    side = named_side(arms_prompt)
    return PartPlan(legs_prompt, arms_prompt, legs_action, arms_action,
                    side if side is not None and side[1] == "hand" else None)


def clauses(text: str) -> list[str]:
    """The clauses of a prompt: cut at its connectors and before a participle that follows a verb
    ("jogs along waving" -> "jogs along", "waving"), each tidied, empty ones dropped."""
    t = split_words(text).strip()
    as_as = [m.span() for m in re.finditer(r"\bas\s+\w+(?:\s+\w+)?\s+as\b", t)]  # "as fast as he can"
    cuts = {m.start() for m in CONNECTOR.finditer(t) if not any(a <= m.start() < b for a, b in as_as)}
    words = list(re.finditer(r"[a-z'-]+", t))
    for prev, w in zip(words[1:], words[2:]):  # a participle after a verb: "jogs along waving"
        start = max([c for c in cuts if c < w.start()], default=0)
        before = _tidy(t[start:w.start()])
        if (w.group(0).endswith("ing") and len(w.group(0)) > 4 and not CONNECTOR.fullmatch(prev.group(0))
                and len(before.split()) >= 2 and not SUBJECT.fullmatch(before)):
            cuts.add(w.start())
    bounds = [0] + sorted(cuts) + [len(t)]
    return [c for c in (_tidy(t[a:b]) for a, b in zip(bounds, bounds[1:])) if c]


def _subject(t: str) -> str:
    m = SUBJECT.match(t)
    return m.group(0) if m else "a person"


def plan_parts(text: str, classify=None) -> PartPlan | None:
    """The legs and arms prompts of a two-things-at-once prompt (module docstring), or None.
    ``classify(clauses) -> actions`` (an action name or None each) names the action of clauses the
    action patterns do not recognise (``parts.clause_classifier``: the nearest training caption)."""
    t = split_words(text).strip()
    if ORDER_WORDS.search(t):
        return None
    spans = action_spans(t)
    legs = max((sp for sp in spans if sp[2] in BODY), key=lambda sp: (sp[1] - sp[0], -sp[0]), default=None)
    arms = None
    if legs is not None:  # a gesture outside the locomotion's span; one a connector parts from it first
        apart = [sp for sp in spans if sp[2] in ARMS and (sp[1] <= legs[0] or sp[0] >= legs[1])]
        joined = [sp for sp in apart if CONNECTOR.search(t, min(sp[1], legs[1]), max(sp[0], legs[0]))]
        arms = (joined or apart or [None])[0]
    if legs is None or arms is None:
        return _plan_by_clauses(t, classify) if classify is not None else None
    first, second = sorted([legs, arms])
    found = list(CONNECTOR.finditer(t, first[1], second[0]))
    # "waves with his right hand while walking": the "with" says how, the "while" joins
    joins = [m for m in found if m.group(0) != "with"] or found
    cut = joins[0].start() if joins else second[0]
    a, b = _tidy(t[:cut]), _tidy(t[cut:])
    if not a or not b:
        return None
    legs_clause, arms_clause = (a, b) if first is legs else (b, a)
    legs_action = _part_action(legs_clause, BODY) or legs[2]
    arms_action = _part_action(arms_clause, ARMS) or arms[2]
    return _plan(_with_subject(legs_clause), _with_subject(arms_clause), legs_action, arms_action)


STOP = frozenset("a an the this that his her their its my your our one some is are was be being been it he she they "
                 "him them who while as and with of to in on at for from by".split())


def _content(clause: str) -> list[str]:
    """The clause's words that are not its subject or small words."""
    m = SUBJECT.match(clause)
    rest = clause[m.end():] if m else clause
    return [w for w in re.findall(r"[a-z'-]+", rest) if w not in STOP]


NOT_VERBS = frozenset("something anything nothing everything morning evening ceiling building clothing ring string "
                      "thing arms hands legs feet knees fists shoulders fingers toes elbows hips steps stairs "
                      "circles times ways yards metres meters sides others friends its his this is was has does "
                      "as us plus".split())
SUBJECT_VERB = re.compile(r"^(?:he|she|it|someone|somebody|(?:a|an|the|this|that|one)\s+(?:[a-z-]+\s+){0,2}?[a-z-]+)"
                          r"\s+([a-z]+s)\b")


def _has_verb(clause: str) -> bool:
    """Whether a clause says what someone does: a verb of the caption tables, a participle, a
    verb after its subject ("the player hurls", "she lifts") or leading the clause ("tosses the
    ball"). "like an elderly person" or "with youthful vigour" say how, and are left alone."""
    from ..data.captions import table_verbs

    verbs = table_verbs()
    if any(w not in NOT_VERBS and (w in verbs or w + "s" in verbs or (len(w) > 4 and w.endswith(("ing", "ed"))))
           for w in _content(clause)):
        return True
    m = SUBJECT_VERB.match(clause)
    if m and m.group(1) not in NOT_VERBS and m.group(1) not in STOP:
        return True
    first = re.match(r"[a-z]+", clause)
    return bool(first and first.group(0).endswith("s") and first.group(0) not in NOT_VERBS | STOP
                and len(first.group(0)) > 3)


def _plan_by_clauses(t: str, classify) -> PartPlan | None:
    """Two things at once read clause by clause, ``classify`` naming what the patterns do not."""
    cs = clauses(t)
    if len(cs) < 2:
        return None
    acts = [_part_action(c, LEGS) or _part_action(c, ARMS) for c in cs]
    for i, c in enumerate(cs):  # "swinging the arms around in circles": arms, whatever its words' gait
        if acts[i] in LEGS and re.search(r"\b(?:" + HAND_WORDS + r")\b", c) and not _part_action(c, ARMS):
            acts[i] = None
    todo = [i for i, a in enumerate(acts) if a is None and len(_content(cs[i])) >= 2 and _has_verb(cs[i])]
    for i, a in zip(todo, classify([cs[i] for i in todo]) if todo else []):
        acts[i] = a
    li = next((i for i, a in enumerate(acts) if a in LEGS), None)
    ai = next((i for i, a in enumerate(acts) if a in ARMS and i != li), None)
    if li is None or ai is None:
        return None
    subject = _subject(t)
    return _plan(_with_subject(cs[li], subject), _with_subject(cs[ai], subject), acts[li], acts[ai])
