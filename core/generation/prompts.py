"""Checks on user text before it reaches the tokenizer: clear errors instead of odd output."""
from __future__ import annotations

import unicodedata

from ..errors import ShapeMoveError

MAX_PROMPT_CHARS = 1000


def check_prompt(text, what: str = "prompt", allow_empty: bool = False) -> str:
    """Return the prompt with surrounding whitespace removed, or raise ShapeMoveError naming the problem."""
    if text is None or (isinstance(text, str) and not text.strip()):
        if allow_empty:
            return ""
        raise ShapeMoveError(f"the {what} is empty: describe a motion, e.g. 'a person walks forward and waves'")
    if not isinstance(text, str):
        raise ShapeMoveError(f"the {what} must be text, got {type(text).__name__}")
    text = text.strip()
    if len(text) > MAX_PROMPT_CHARS:
        raise ShapeMoveError(f"the {what} is {len(text)} characters long; keep it under {MAX_PROMPT_CHARS}")
    bad = sorted({f"U+{ord(c):04X}" for c in text if unicodedata.category(c) in ("Cc", "Cf", "Cs", "Co", "Cn")
                  and c not in "\t\n"})
    if bad:
        raise ShapeMoveError(f"the {what} contains control or invisible characters ({', '.join(bad[:5])}); "
                             "remove them and try again")
    if not any(c.isalpha() for c in text):
        raise ShapeMoveError(f"the {what} has no words in it: {text[:40]!r}")
    return " ".join(text.split())
