"""A stop played on a captured take, where the codes cannot carry the gait.

A stop, a count of steps or a distance is cut in the codes (``stop_words.py``): the decoder itself
brings a forward walk to a halt. A backward walk's codes decode as a body sliding with its feet near
the floor (``gait_steps.py``: "a woman walks backwards and stops", seeds 0 and 1, slid 2.3-2.6 m with
no ankle 4 cm off the floor; so did every candidate of "a man walks backwards 3 metres"). So when the
chosen candidate of a gait asked to stop does not step, the captured takes of that gait compete
instead, each cut where the words stop it and held there, standing (``stop_frame``):

- after the counted step: ``SETTLE`` frames after the take's ``steps``-th foot strike
  (``gait_steps.contact_strikes`` of the take's measured contacts), the feet both down;
- where its root is ``metres`` from where it started;
- else after ``stop_words.GOING_SECONDS`` when no length is asked, at half the length when one is.

The held pose is the take's at its cut (both feet on the floor, as far apart as that stride left
them); the length is the one asked, or the cut and ``stop_words.STAND_SECONDS`` when none is.

    k = stop_frame(window.contacts, window.root, steps=3, metres=None, going=60)
"""
from __future__ import annotations

import numpy as np

from .gait_steps import contact_strikes
from .stop_words import from_start

SETTLE = 4    # frames after the counted strike: the foot settles, the other still down


def stop_frame(contacts, root, steps: int | None, metres: float | None, going: int) -> int | None:
    """The frame a captured take is cut at for its stop (module doc): ``contacts`` (T, 4) of joints
    7, 8, 10, 11, ``root`` (T, 3) metres; ``going``: the frames it goes when neither ``steps`` nor
    ``metres`` is asked. None when the take strikes fewer times or never gets that far."""
    n = len(contacts)
    if steps is not None:
        strikes = contact_strikes(contacts)
        return min(n, strikes[steps - 1] + SETTLE) if len(strikes) >= steps else None
    if metres is not None:
        far = np.flatnonzero(from_start(np.asarray(root)[:, None]) >= metres)
        return int(far[0]) + 1 if len(far) else None
    return max(1, min(n, int(going)))
