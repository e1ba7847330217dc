"""How the captured takes that compete are done: the manner the words ask ("walks proudly", "a
tired man walks": the plan's ``Words.manner``) against the manners of the takes of the action
(``captured_takes.TakePool.manner``: what their captions say, read by the prompt's own reader).

- A manner asked that some take of the action is done in: those takes alone compete, and the T5's
  samples do not (the TMA that chooses hardly tells a proud walk from a plain one).
- A manner asked that no take of the action is done in: the plain takes compete, the samples too,
  and the motion says the manner was not shown (``unmet_note``): "runs away scared" (no scared run)
  drew Bandai's sad run as readily as a plain one, which a user asking for fear does not expect
  either. Where the action has no plain take, every take competes.
- A manner asked with a fast pace ("an old man walks quickly") whose takes that compete all go
  slower than the action's typical pace: the plain takes compete, and the motion says why
  (``too_slow``, ``slower_note``); the elderly walks went at 0.75 m/s, quickly or not.
- None asked: the plain takes (no manner in their captions) compete where the action has any: "a
  man bows" drew the bow "like in a musical", or "with a swagger, like a street thug", as readily as
  the plain one; a plain walk, CMU's "walk, exaggerated stride".
- No plain take of the action (the library's waves goodbye, walks backward, sprints and guides are
  all Bandai's styled ones), and none asked or the one asked not among them: the takes done in the
  styles nearest a plain performance compete (``MILD``: energetically, happily, proudly), where the
  action has any, else every take; a sprint's every take competes (its mild dashes go at a run's
  pace, and the fastest are the angry, the thug's and the masculine one). "A small child waves
  goodbye" played the street thug's wave, "a scared woman backs away slowly" his walk backward.

    manner = manner_kept(words.manner, pool.manners_of("walk"))
    competes = done_as(window.manner, manner)
"""
from __future__ import annotations

from ..plan.vocabulary import MANNER_SAID


class _Kept:
    """Which takes compete, where it is no one manner (``manner_kept``)."""

    def __init__(self, name: str):
        self.name = name

    def __repr__(self) -> str:
        return self.name


ANY = _Kept("ANY")         # every take competes, whatever its manner
MILD_ONLY = _Kept("MILD")  # the takes done in a ``MILD`` style compete
MILD = frozenset({"energetic", "happy", "proud"})   # the styles nearest a plain performance
SPEED_IS_THE_POINT = frozenset({"sprint"})   # no mild style: Bandai's mild dashes go 2.5-3.2 m/s, a run's pace


def manner_kept(asked: str | None, manners: set, action: str | None = None):
    """The manner of the takes that compete (None: the plain ones), ``MILD_ONLY`` or ``ANY``; ``asked``: the
    manner the words ask (None: none); ``manners``: those of the action's takes (None for a plain
    one; empty when the words name no action or it has no take); ``action``: theirs (a sprint: no
    mild style alone)."""
    if asked is not None and asked in manners:
        return asked
    if None in manners:
        return None
    return MILD_ONLY if MILD & set(manners) and action not in SPEED_IS_THE_POINT else ANY


def done_as(manner: str | None, kept) -> bool:
    """Whether a take done in ``manner`` (None: plainly) competes where ``manner_kept`` gave ``kept``."""
    return kept is ANY or manner == kept or (kept is MILD_ONLY and manner in MILD)


def shown(asked: str | None, windows) -> bool:
    """Whether a take done in the ``asked`` manner is among the ``windows`` that compete (the T5's
    samples then do not)."""
    return asked is not None and any(w.manner == asked for w in windows)


def unmet_note(asked: str | None, action: str | None, windows) -> str:
    """What the motion says when the manner asked is not shown: no take of ``action`` done so
    competes ("" when it is, or none was asked)."""
    if asked is None or shown(asked, windows):
        return ""
    what = f"of {action!r} " if action else ""
    return f"not done {MANNER_SAID.get(asked, asked)}: no captured take {what}is done so (the words are read as a whole)"


def too_slow(words, asked: str | None, manner, windows, speeds: dict, body) -> bool:
    """Whether the words (``plan.words.Words``) ask the gait ``asked`` fast in a ``manner`` whose takes
    that compete (``windows``) all go slower than its typical pace (``speeds``, on the average body
    ``body``) on their performers ("an old man walks quickly": the elderly walks at 0.75 m/s)."""
    from .typical_pace import on_performer, take_speed

    typical = speeds.get(asked) if asked else None
    return (words.pace == "fast" and typical is not None and manner is not None and manner is not ANY
            and bool(windows) and all(take_speed(w) < on_performer(typical, w, body) for w in windows))


def slower_note(asked: str, action: str | None) -> str:
    """What the motion says when a manner is asked with a fast pace and every take done so is slower
    than the action's typical pace: the plain takes compete instead."""
    what = f"of {action!r} " if action else ""
    return f"not done {MANNER_SAID.get(asked, asked)}: the captured takes {what}done so are slower than asked"
