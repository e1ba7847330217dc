"""On the spot: a gait the words keep in place ("jogs in place", "marches on the spot") steps where
it stands.

The training data holds one caption of stepping in place, so every sample and retrieved clip of
"a person jogs in place" travels (the default model: 7.5-9.5 m in 4 s; `travel_words` can only set
aside candidates, and none stays). When the plan keeps a gait in place (``plan.words.Words.in_place``:
a gait and "in place" or "on the spot"; for a single prompt any action the words keep in place,
``Words.travel.in_place``: "hops on the spot"), and the chosen motion's root still travels more than
``travel_words.SLACK`` (half a metre), its strides are scaled to travel that far
(``stride_scale.scaled_strides``: the root's path and the feet's reach shortened together, so a
planted foot stays planted and lands under the hip; the knees placed again, so a lifted foot still
lifts the knee); then the feet are planted again (``track.replanted``): an edit like a turn the
words name (``turn_words.py``), so the motion keeps no tokens. A loop of such a prompt is cut from
its samples stepped on the spot the same way, to ``LOOP_ALLOWED`` (``loop.generate_loop``).
"""
from __future__ import annotations

from .stride_scale import scaled_strides
from .travel_words import SLACK

LOOP_ALLOWED = 0.1   # metres a loop's sample kept in place may travel (a cycle advances a few cm)


def spot_scale(joints, on_spot: bool, allowed: float = SLACK) -> float:
    """The stride scale that keeps (T,22,3) ``joints`` within ``allowed`` metres of travel when the
    plan keeps a gait in place (``on_spot``: ``Words.in_place``) and they travel further; 1 otherwise."""
    if not on_spot:
        return 1.0
    return held_scale(joints, allowed)


def held_scale(joints, allowed: float) -> float:
    """The stride scale that keeps (T,22,3) ``joints`` within ``allowed`` metres of root travel
    along its path (1 when they travel no further)."""
    from .track import travel

    if len(joints) < 4:
        return 1.0
    went = float(travel(joints)[-1])
    return allowed / went if went > allowed else 1.0


def spot_track(track, on_spot: bool, allowed: float = SLACK):
    """``track`` (a ``track.Track``) stepping on the spot when the plan keeps a gait in place and
    the track travels more than ``allowed`` metres, scaled to travel that far (``spot_scale``); None
    otherwise (a loop allows ``LOOP_ALLOWED``: its advance repeats every cycle)."""
    from .track import Track

    scale = spot_scale(track.joints, on_spot, allowed)
    return None if scale >= 1.0 else Track(scaled_strides(track.joints, scale), track.contacts)


def on_the_spot(motion, body, on_spot: bool, ik_refine_iters: int = 10):
    """``motion`` stepping on the spot (``spot_track``), feet planted again; the motion itself when
    the plan does not keep a gait in place (``on_spot``) or it does not travel."""
    from .track import replanted, track_of

    spot = spot_track(track_of(motion), on_spot)
    return motion if spot is None else replanted(motion, body, spot, ik_refine_iters)
