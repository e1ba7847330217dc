"""Hopping or jumping on one foot: no capture does it. The data's 33 hops (HDM05 ``hopBothLegs``)
and every jump land on both feet, and the T5 learnt from them, so "a child hops on one foot"
plays hops on both feet; the motion says so rather than claiming the words were met. The words
are the plan's (``plan.words.Words.one_foot``, ``vocabulary.ONE_FOOT``).

    one_foot_note(read_words("a child hops on one foot"), "hop")   # "no capture hops on one foot: ..."
"""
from __future__ import annotations


def one_foot_note(words, asked: str | None) -> str:
    """The note for words (``plan.words.Words``) asking the action ``asked`` on one foot ("" when they
    do not, or ``asked`` is not one of ``vocabulary.ONE_FOOT_ACTIONS``)."""
    from ..data.actions import action_verb
    from ..plan.vocabulary import ONE_FOOT_ACTIONS

    if not words.one_foot or asked not in ONE_FOOT_ACTIONS:
        return ""
    return f"no capture {action_verb(asked)} on one foot: every take and sample lands on both feet"
