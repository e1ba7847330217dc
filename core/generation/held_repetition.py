"""A take of an action done over and over is no answer when it stops half way.

A take of one repetition that does not loop (``take_loop.looped_repetition`` finds no seam in it:
HDM05 mm rotateArmsBothBackward 011, two arm circles in 1.9 s) asked for 4 s is held on its last
pose for the other 2.1 s, and the TMA still found it nearer "an athlete does arm circles" (0.898)
than the single circles that loop to the end (0.80 to 0.89): the user got arms circling for half
the time and a person standing for the rest. For an action done over and over by its nature
(``actions.REPEATED``), a window held for more than ``MOST_HELD`` of its frames competes only when
every take offered is held as long; where the words count the repetitions ("three arm circles"),
a take cut to them is held on purpose and this does not apply.
"""
from __future__ import annotations

MOST_HELD = 0.25   # share of a window's frames held on its last pose, above it a repetition has stopped


def performed(windows: list, asked: str | None, times: int | None = None, again: bool = False) -> list:
    """``windows`` (``captured_takes.Window``) without those held too long for the repeated action
    ``asked`` (module docstring), or one the words ask ``again`` and again, unless none is left;
    unchanged for another action or a count."""
    from ..data.actions import REPEATED

    if (asked not in REPEATED and not again) or times is not None:
        return windows
    going = [w for w in windows if w.held <= MOST_HELD * len(w.rotations)]
    return going or windows
