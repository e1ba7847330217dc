"""Captured takes in the same pool as the T5's samples: one choice among finished motions.

The codec flattens what it carries badly (a front kick's ankle comes back at a fifth of its height,
docs/codec.md), so a captured performance offered as codes never reaches the user as performed.
Here the takes themselves compete: the built-in motion library (``data/motion_library.py``,
``library.npz`` of the model folder) and the user's own library (``Generator.add_library``), both
in one ``TakePool``. For a prompt:

- the takes of the action the words ask for (the plan's reading, or the planner's reading for a
  part) nearest the prompt by caption (the TMA text embedding of the prompt against
  each take's captions), and the takes nearest by caption whatever their action, ``TAKES`` in
  all, drawn by the request's seed from the ``POOL`` x as many nearest (another seed, other takes);
  a drawn take whose window would not compete (below, and a plain gait's takes too slow, too fast,
  stopping or turning: ``typical_pace.py``) gives its place to another, drawn the same way, then
  to the next nearest of the asked action: "she jogs for a while" (seed 0) drew three jogs too slow
  for a plain jog and was left with the T5's samples;
  the user's own clips come first: their nearest by caption and their nearest of the asked action;
  where the words name no action the plan knows, only takes whose captions say nearly what the
  prompt says compete (``NAMELESS_FLOOR``): "a person plays the guitar" (no action read) played a
  sprint 15 m at 0.69, "a soldier salutes" a limp at 0.62, "a man rows a boat" a spin jump at 0.82;
- each gives one window of the requested length (one of its busiest, ``busiest_start``); a take shorter
  than asked plays on as a loop of its own cycle where it repeats (``take_loop.py``: jumping jacks,
  arm circles), else it is held on its last pose for the rest (a kick, then standing); with no
  length asked a take plays whole, at least ``UNASKED_SECONDS``;
- a named side ("kicks with the right leg") mirrors a take whose other side moves most
  (``part_compose.needs_mirror``; ``data/mirror.py``'s rotations);
- each window's features, on the performer's own body (``ClipProcessor.pose_on``), join the
  samples' decoded features, and the TMA chooses among them all (``rerank.CandidatePicker``), a
  take of the asked action credited ``ACTION_BONUS``; when the words name an action, a take of
  another one does not compete (``action_credit``: "sits down" is not played as the lying-down take
  nearest its words); for an action no take is of, the takes that can stand in for it are drawn and
  compete, made into it (``stand_in_takes.py``: a lie-down that settles played to where it sits, a
  put-down's bend backwards; ``stands_in``).

A window kept is moved onto the requested body by its own rotations with its feet planted
(``retarget.planted_retarget``), never through the codes, and says where it came from
(``Motion.provenance``: "captured: HDM05 bd kickLFront 003 (CC BY-SA 3.0)").

    pool = TakePool(body, MotionLibrary.load(path), embed)    # embed(texts): unit TMA text vectors
    pool.set_vectors(None)                                    # the captions embedded (or the file's own)
    windows = pool.windows(embed(["a man throws a jab"])[0], "punch", seed=0, frames=80)
    motion = captured_motion(windows[0], body, betas)
"""
from __future__ import annotations

import random
from collections import OrderedDict
from collections.abc import Callable
from itertools import islice
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from ..scene.motion_file import Motion
from ..data.actions import MOVES_ON, REPEATED
from ..plan.vocabulary import COUNTED, GAITS, KEPT_UP, POSTURE_CHANGES
from .floor_sit import SIT, SIT_FROM, sit_end
from .stand_in_takes import STAND_IN, played_as, stand_in_span
from .repeated_takes import cut_for, repeated_stretch
from .straight_gait import STRAIGHTENED, line_stretch, straightened
from .take_loop import looped_gait, looped_repetition, looped_steps, looped_take

TAKES = 5              # captured windows offered per prompt
POOL = 2               # drawn by the seed from the POOL x TAKES nearest
NEAREST = 2            # of them, at most this many by caption alone when the words name an action
ACTION_BONUS = 0.3     # TMA cosine credited to a take of the asked action (tuning paraphrases, docs/library.md)
UNASKED_SECONDS = 4.0  # the least a take plays when the length is the model's
BUSIEST = 2            # a long take's busiest windows, one drawn by the seed
KEPT = 16              # takes kept read at once (rotations as matrices)
LAST_POSE_HELD = "its last pose is held"   # said of a take shorter than asked (``captured_motion``)
OTHER_WAY = frozenset({"walk backward"})   # specific forms that compete only when asked by name: another way,
ADDS_TURN = frozenset({"spin jump", "spin kick", "cartwheel"})   # or a turn the generic words do not ask
NAMELESS_FLOOR = 0.9   # TMA caption cosine from which a take competes when the words name no action
USER_FLOOR = 0.5       # TMA caption cosine from which the user's nearest clip is offered whatever its action


@dataclass
class Window:
    """A stretch of a take, ready to be scored and planted."""
    rotations: np.ndarray   # (T,24,3,3), the held frames included
    root: np.ndarray        # (T,3)
    contacts: np.ndarray    # (T,4)
    rest: np.ndarray        # (24,3) rest joints of the performer's body
    features: np.ndarray    # (T-1,263) on the performer's body, for the TMA
    action: str
    clip_id: str
    provenance: str
    held: int = 0           # frames held on the last pose
    mirrored: bool = False
    looped: int = 0         # frames of the take's own cycle played again (take_loop.py)
    cut: int = 0            # frames of the repetitions asked that the length asked leaves out
    note: str = ""          # why this take stands in for what was asked (travel_words.backward_taken)
    seated: bool = False    # it starts where its take sits on the floor (a lie-down after a sit: floor_sit.py)
    manner: str | None = None   # how its take is done, as its captions say (``take_manner``)

    @property
    def arrays(self) -> dict:
        """The window as a take's arrays (``retarget.planted_retarget``, ``retarget.shaped_take``)."""
        return {"rotations": self.rotations, "root": self.root, "rest": self.rest, "contacts": self.contacts}


def hold(rotations, root, contacts, frames: int, stands: bool = True):
    """A take shorter than ``frames`` held on its last pose (its contacts, or, where it ``stands``,
    both feet down when the last frame has none) for the rest. A sit on the floor does not stand:
    its feet may be off the floor, and planting them there pulled the legs 12 cm off the pose."""
    extra = frames - len(rotations)
    if extra <= 0:
        return rotations, root, contacts
    last = contacts[-1] if contacts[-1].any() or not stands else np.ones(4, np.uint8)
    return (np.concatenate([rotations, np.repeat(rotations[-1:], extra, 0)]),
            np.concatenate([root, np.repeat(root[-1:], extra, 0)]),
            np.concatenate([contacts, np.repeat(last[None], extra, 0)]).astype(np.uint8))


def mirrored(rotations, root, contacts):
    """The mirror image of a take (``data/mirror.py``: left and right swapped, x negated)."""
    from ..data.mirror import mirror_contacts, mirror_rotations

    r = np.asarray(root, np.float32).copy()
    r[:, 0] *= -1
    return mirror_rotations(rotations).astype(np.float32), r, mirror_contacts(contacts)


class TakePool:
    """The takes that compete: the built-in library's and the user's files (read when offered)."""

    def __init__(self, body, library=None, embed=None, ik_refine_iters: int = 10):
        """``library``: a ``MotionLibrary`` or None; ``embed(texts) -> (N,E)`` unit TMA text vectors
        (the library's own are used when it was made with the same TMA, ``vectors_ok``)."""
        from .retarget import processor

        self.body, self.library, self.embed = body, library, embed
        self.proc = processor(body, ik_refine_iters)
        self.ik_refine_iters = ik_refine_iters
        n = 0 if library is None else len(library)
        self.actions: list[str] = list(library.actions) if library is not None else []
        self.files: list[Path | None] = [None] * n
        self.ids: list[str] = [str(c) for c in library.a["clip_ids"]] if library is not None else []
        self.vectors = np.zeros((n, 0), np.float32)
        self._cache: OrderedDict = OrderedDict()
        self._both: dict[int, bool] = {}
        self._spans: dict[tuple[int, str], tuple[int, int] | None] = {}
        self._manners: dict[int, str | None] = {}
        self._sideways: dict[int, bool] = {}
        self.user_captions: dict[int, list[str]] = {}

    def __len__(self) -> int:
        return len(self.actions)

    def set_vectors(self, vectors: np.ndarray | None) -> None:
        """The library's caption vectors, or None: embedded here (each take's captions, averaged)."""
        if self.library is None:
            return
        if vectors is None:
            if self.embed is None:
                raise ShapeMoveError("the motion library's captions need the model's TMA to be compared with a prompt")
            from ..data.motion_library import mean_caption_vectors

            vectors = mean_caption_vectors(self.embed, [self.library.captions(k) or [self.actions[k] or "a person moves"]
                                                        for k in range(len(self.library))])
        self.vectors = np.asarray(vectors, np.float32)

    def add_files(self, ids: list[str], paths: list[Path], captions: list[str]) -> None:
        """The user's captioned clips (read as takes when first offered: ``library_takes.read_take``)."""
        from ..data.actions import find_actions

        if not ids:
            return
        if self.embed is None:
            raise ShapeMoveError("a library's captions need the model's TMA to be compared with a prompt")
        v = self.embed(list(captions))
        self.vectors = v if not len(self.vectors) else np.concatenate([self.vectors, v])
        self.actions += [(find_actions(c) or [""])[0] for c in captions]
        self.user_captions.update({len(self.files) + k: [c] for k, c in enumerate(captions)})
        self.files += [Path(p) for p in paths]
        self.ids += list(ids)

    def is_user(self, i: int) -> bool:
        return self.files[i] is not None

    def take(self, i: int) -> dict:
        """Take ``i`` as arrays: rotations (T,24,3,3), root, contacts, rest, betas, provenance."""
        if i in self._cache:
            self._cache.move_to_end(i)
            return self._cache[i]
        import torch

        if self.files[i] is None:
            t = self.library.take(i)
            with torch.no_grad():
                rest = self.body.rest_joints(torch.as_tensor(t.betas)[None])[0].numpy()
            if abs(t.fps - FPS) > 1e-6:
                raise ShapeMoveError(f"motion library take {t.clip_id} is at {t.fps:g} fps, not {FPS}")
            out = {"rotations": t.rotations, "root": t.root, "contacts": t.contacts, "rest": rest, "betas": t.betas,
                   "provenance": t.provenance}
        else:
            from .library_takes import read_take

            t = read_take(self.files[i], self.body, self.ik_refine_iters)
            out = {k: t[k] for k in ("rotations", "root", "contacts", "rest", "betas")}
            out["provenance"] = f"captured: {self.files[i].name} (your library)"
        self._cache[i] = out
        if len(self._cache) > KEPT:
            self._cache.popitem(last=False)
        return out

    def posed(self, i: int) -> np.ndarray:
        """Take ``i`` whole, posed on its performer's body: the joints its kept readings are made
        from (``two_handed``, ``stand_in_span``, ``sideways``)."""
        t = self.take(i)
        return self.proc.pose_on(t["rotations"], t["root"], t["betas"], 1.0, t["contacts"])

    def manner(self, i: int) -> str | None:
        """The manner take ``i`` is done in, as its captions say it (``take_manner``; kept)."""
        if i not in self._manners:
            captions = self.user_captions.get(i) or (self.library.captions(i) if self.files[i] is None else [])
            self._manners[i] = take_manner(captions)
        return self._manners[i]

    def manners_of(self, action: str | None, keep: Callable[[int], bool] | None = None) -> set:
        """The manners of the takes of ``action`` (None among them for a plain take); ``keep(i)``:
        of those it keeps only."""
        return {self.manner(i) for i in range(len(self))
                if action and self.actions[i] == action and (keep is None or keep(i))}

    def sideways(self, i: int) -> bool:
        """Whether take ``i`` goes to the side at least as far as forward, whole, on its performer
        (``travel_words.goes_sideways``; kept)."""
        if i not in self._sideways:
            from .travel_words import goes_sideways

            t = self.take(i)
            self._sideways[i] = goes_sideways(self.proc.features(self.posed(i), t["rotations"], t["contacts"]))
        return self._sideways[i]

    def two_handed(self, i: int) -> bool:
        """Whether take ``i`` makes its gesture with both hands (``hands_asked.made_with_both``; kept)."""
        if i not in self._both:
            from .hands_asked import made_with_both

            self._both[i] = made_with_both(self.posed(i))
        return self._both[i]

    def stands_in(self, i: int, asked: str | None) -> bool:
        """Whether take ``i`` can be made into the ``asked`` action it stands in for (a lie-down that
        settles where it sits, a put-down whose feet hold still through its bend)."""
        return self.stand_in_span(i, asked) is not None

    def stand_in_span(self, i: int, asked: str | None) -> tuple[int, int] | None:
        """The frames of take ``i`` that play the ``asked`` action it stands in for, or None
        (``stand_in_takes.stand_in_span`` on the take posed on its performer; kept)."""
        if STAND_IN.get(asked or "") != self.actions[i]:
            return None
        if (i, asked) not in self._spans:
            self._spans[(i, asked)] = stand_in_span(asked, self.actions[i], self.posed(i))
        return self._spans[(i, asked)]

    def nearest(self, text: np.ndarray, action: str | None, seed: int, count: int = TAKES,
                hands: bool | None = None, competes: Callable[[int], bool] | None = None) -> list[int]:
        """Takes offered for a prompt whose TMA text vector is ``text`` (see the module docstring);
        ``hands``: a gesture of both hands (True) or one (False): the takes made so, where any is
        (``hands_asked.py``); ``competes(i)``: whether take ``i`` would compete, when given: a drawn
        take that would not gives its place to another drawn the same way, then, among the takes of
        the asked action, to the next nearest (a plain jog's slow takes do not use up the places of
        those at a jog's pace)."""
        if not len(self) or not len(self.vectors):
            return []
        sims = self.vectors @ np.asarray(text, np.float32)
        rng = random.Random(int(seed))
        chosen: list[int] = []
        passed: dict[int, bool] = {}

        def ok(i: int) -> bool:
            if competes is None:
                return True
            if i not in passed:
                passed[i] = bool(competes(i))
            return passed[i]

        def draw(ids, k, further: bool):
            ids = [i for i in sorted(ids, key=lambda i: -sims[i]) if i not in chosen]
            near, rest = ids[:POOL * k], iter(ids[POOL * k:])
            if hands is not None:   # the nearest made with the hands asked, looked at in order until enough
                made = (i for i in ids if self.two_handed(i) == hands)
                first = list(islice(made, POOL * k))
                if first:   # and the next nearest so made after them
                    near, rest = first, made
            picked = sorted(rng.sample(range(len(near)), min(k, len(near))))
            kept = [near[j] for j in picked if ok(near[j])]
            left = [j for j in range(len(near)) if j not in picked]
            while len(kept) < k and left:   # in place of those that would not compete: drawn the same way
                j = left.pop(rng.randrange(len(left)))
                if ok(near[j]):
                    kept.append(near[j])
            if further:   # then the next nearest
                kept += list(islice((i for i in rest if ok(i)), k - len(kept)))
            chosen.extend(kept)

        user = [i for i in range(len(self)) if self.is_user(i)]
        if user:   # the user's own: the nearest by caption, and the nearest of the asked action
            best = max(user, key=lambda i: sims[i])
            if sims[best] >= USER_FLOOR and ok(best):
                chosen.append(best)
            mine = [i for i in user if action and self.actions[i] == action and i not in chosen and ok(i)]
            if mine:
                chosen.append(max(mine, key=lambda i: sims[i]))
        named = [i for i in range(len(self)) if action and self.actions[i] == action]
        if action in STAND_IN and not named:   # no take of it: the takes that can stand in (stand_in_takes.py)
            named = [i for i in range(len(self)) if self.stands_in(i, action)]
        draw(named, max(0, count - len(chosen) - NEAREST) if named else 0, True)
        near = range(len(self)) if action else [i for i in range(len(self)) if sims[i] >= NAMELESS_FLOOR]
        draw(near, max(0, count - len(chosen)), False)
        return chosen

    def window(self, i: int, frames: int, seed: int, side=None, longest: int | None = None,
               times: int | None = None, straight: bool = False, asked: str | None = None,
               seated: bool = False, repeat: bool = False) -> Window:
        """Take ``i`` cut to ``frames`` (the seed picks the start), or held to it when shorter;
        ``longest``: the length is the model's (``frames`` the least), the take plays whole up to
        ``longest`` frames. ``side``: ("left" | "right", "hand" | "foot") mirrors a take whose
        other side moves most. A take of a counted action plays its repetitions, ``times`` of them
        when asked (``repeated_takes.py``), all of them when the length is the model's, however long;
        a take of a change of posture (``plan/vocabulary.POSTURE_CHANGES``: getting up, lying down) is cut to
        its end. ``straight``: a take of a plain gait is played off its bend (``straight_gait.py``)
        and, shorter than asked, loops on its last stride (``take_loop.looped_gait``); a take of
        another gait that turns round plays its longest stretch along a line (``line_stretch``); a take of any
        other gait (``vocabulary.GAITS``: two sneaking steps) shorter than asked and without two
        cycles of its own loops on its last stride too, else on its last step and the step's mirror
        image, else (a cycle whose contacts do not show its steps) whole, as one repetition. A take of
        an action that goes somewhere as it repeats (``actions.MOVES_ON``: a hop) loops only when it
        is the action ``asked``: "a child toddles forward" chose six looped hops among the takes nearest
        by caption. A take standing in for an action no take is of (``stand_in_takes.py``) is made
        into it first: a lie-down played to where it sits, a put-down backwards. A lie-down asked
        ``seated`` (after a segment that sat) plays from where its take sits on the floor
        (``floor_sit.sit_end``) to its end. ``repeat``: the words ask a counted action again and again
        (``plan.words.Words.again``: "jumps up and down"): a take of one repetition of it loops as a
        take of a repeated action does, moving on where the repetition does (a jump forward)."""
        from .part_compose import needs_mirror

        t = self.take(i)
        rot, root, con, exact = t["rotations"], t["root"], t["contacts"], False
        action, provenance, from_seat = self.actions[i], t["provenance"], False
        pose = lambda r, rt, c: self.proc.pose_on(r, rt, t["betas"], 1.0, c)  # noqa: E731
        span = self.stand_in_span(i, asked)   # a sit, a pick-up (stand_in_takes.py)
        if span is not None:
            rot, root, con, action, said = played_as(asked, rot, root, con, span)
            provenance += f", {said}"
        elif action == SIT_FROM and seated:   # a lie-down after a sit: on from where it sits (floor_sit.py)
            end = sit_end(pose(rot, root, con))
            if end is not None:
                rot, root, con = rot[end - 1:], root[end - 1:], con[end - 1:]
                provenance += ", from its sit on the floor"
                from_seat = True
        if straight and action in GAITS and action not in STRAIGHTENED:   # along a line: not its turn round
            lo, hi = line_stretch(pose(rot, root, con))
            if hi - lo < len(rot):
                rot, root, con = rot[lo:hi], root[lo:hi], con[lo:hi]
                provenance += f", its {lo / FPS:.1f}-{hi / FPS:.1f} s along a line"
        if cut_for(action, times):
            def posed(r, rt, c):
                j = pose(r, rt, c)
                return j, self.proc.features(j, r, c)

            rot, root, con, exact = repeated_stretch(rot, root, con, posed, action, times, seed)
        n = len(rot)
        want = min(max(frames, n), longest) if longest is not None else frames
        if exact and longest is not None:   # the length is the model's: every repetition asked plays
            want = max(frames, n)
        if n <= want:
            lo = 0
        else:   # a change of posture ends where the take does (up, or lying): its busiest stretch may not
            lo = n - want if action in POSTURE_CHANGES else busiest_start(rot, want, seed)
        rot, root, con = (np.asarray(a[lo:lo + want]) for a in (rot, root, con))
        gait = straight and action in STRAIGHTENED
        if gait:
            rot, root = straightened(rot, root, pose(rot, root, con))
        held = looped = 0
        if len(rot) < want:   # a take that repeats plays on as a loop, another is held on its last pose
            again = None      # (a take cut to the repetitions asked is held: a loop would add more)
            if not exact:
                posed_joints = pose(rot, root, con)
                if gait:   # on its last stride
                    again = looped_gait(rot, root, con, posed_joints, want)
                else:
                    again = looped_take(rot, root, con, posed_joints, want)
                    if again is None and action in GAITS:   # on its last stride, else its last step
                        again = looped_gait(rot, root, con, posed_joints, want) or \
                            looped_steps(rot, root, con, posed_joints, want, mirrored)   # and the step's mirror image
                goes_on = action not in MOVES_ON or action == asked   # a hop loops for "hops" only
                repeats = action in REPEATED or repeat and (action in COUNTED or action in KEPT_UP)   # "jumps up and down"
                if again is None and (repeats and goes_on or action in GAITS):
                    again = looped_repetition(rot, root, con, posed_joints, want,   # one arm circle, one gait cycle,
                                              action in GAITS or action in MOVES_ON or   # a jump forward moving on;
                                              repeat and COUNTED.get(action) == "flights")   # a punch on the spot
            if again is not None:
                rot, root, con, first = again
                looped = want - first
            held = want - len(rot)
            rot, root, con = hold(rot, root, con, want, stands=action != SIT)
        joints = pose(rot, root, con)
        flip = side is not None and needs_mirror(joints, *side)
        if flip:
            rot, root, con = mirrored(rot, root, con)
            joints = pose(rot, root, con)
        return Window(rot, root, con, t["rest"], self.proc.features(joints, rot, con), action, self.ids[i],
                      provenance + (", mirrored" if flip else ""), held, flip, looped,
                      max(0, n - want) if exact else 0, seated=from_seat, manner=self.manner(i))

    def held_from(self, w: Window, k: int, frames: int, said: str) -> Window:
        """``w`` cut at frame ``k`` and held there, standing, to ``frames`` (a stop played on the take:
        ``take_stop.py``), its features made again; ``said`` joins its provenance."""
        rot, root, con = hold(w.rotations[:k], w.root[:k], w.contacts[:k], frames)
        return Window(rot, root, con, w.rest, self._features_of(w.clip_id, rot, root, con), w.action, w.clip_id,
                      f"{w.provenance}, {said}", frames - k, w.mirrored, manner=w.manner)

    def mirrored_window(self, w: Window) -> Window:
        """``w``'s mirror image (``mirrored``: left and right swapped), its features made again."""
        rot, root, con = mirrored(w.rotations, w.root, w.contacts)
        said = w.provenance.replace(", mirrored", "") if w.mirrored else w.provenance + ", mirrored"
        return replace(w, rotations=rot, root=root, contacts=con, features=self._features_of(w.clip_id, rot, root, con),
                       mirrored=not w.mirrored, provenance=said)

    def _features_of(self, clip_id: str, rot, root, con) -> np.ndarray:
        """The features of a window's frames ``rot``, ``root``, ``con`` of take ``clip_id``, posed on
        its performer's body (as ``window`` makes them)."""
        t = self.take(self.ids.index(clip_id))
        return self.proc.features(self.proc.pose_on(rot, root, t["betas"], 1.0, con), rot, con)

    def windows(self, text: np.ndarray, action: str | None, seed: int, frames: int, side=None,
                longest: int | None = None, count: int = TAKES, times: int | None = None,
                straight: bool = False, hands: bool | None = None, seated: bool = False,
                competes: Callable[[Window], bool] | None = None, repeat: bool = False) -> list[Window]:
        """One window of each take offered (``nearest``, ``hands`` as there); ``times``: the repetitions
        the words ask; ``straight``: the words ask a plain gait; ``seated``: after a sit; ``repeat``: the
        words ask it again and again (``window``);
        ``competes(window)``: whether a take's window competes, when given: only those are offered,
        up to ``count``, the others' places drawn again (``nearest``)."""
        cut: dict[int, Window] = {}

        def of(i: int) -> Window:
            if i not in cut:
                cut[i] = self.window(i, frames, seed, side, longest, times, straight, action, seated, repeat)
            return cut[i]

        test = (lambda i: competes(of(i))) if competes is not None else None  # noqa: E731
        return [of(i) for i in self.nearest(text, action, seed, count, hands, test)]


def without_last_pose_held(notes: list[str]) -> list[str]:
    """``notes`` but the one saying a take's last pose is held (a motion held elsewhere instead)."""
    return [n for n in notes if LAST_POSE_HELD not in n]


def take_manner(captions: list[str]) -> str | None:
    """The manner a take's ``captions`` give it (``plan.reader.manner_of``, the prompt's reader): the
    one at least half of them say ("A person bows happily." / "A human takes a bow cheerfully."), else
    None (a plain take)."""
    from collections import Counter

    from ..plan.reader import manner_of

    said = Counter(m for m in (manner_of(c) for c in captions) if m is not None)
    if not said:
        return None
    manner, n = said.most_common(1)[0]
    return manner if 2 * n >= len(captions) else None


def action_credit(asked: str | None, action: str) -> float | None:
    """What the choice credits a take of ``action`` for a prompt asking ``asked``: ``ACTION_BONUS``
    for the asked action or a specific form of it (``actions.GENERIC_OF``: a jump forward for a
    jump), nothing when the words name no action or the take has no label, and None for a take of
    another action, which does not compete (no sit take: a lying-down take is not a sit), nor does a
    take of a specific form that travels another way than its generic action (``OTHER_WAY``: a walk
    backward is no walk) or turns where it does not (``ADDS_TURN``: "bounces up off the ground" is
    no spin jump, "kicks" no spinning kick, "turns around" no cartwheel)."""
    from ..data.actions import GENERIC_OF

    if not asked or not action:
        return 0.0
    if action in OTHER_WAY | ADDS_TURN and asked != action:   # "walks back" after a turn goes back the way it came
        return None
    return ACTION_BONUS if action == asked or asked in GENERIC_OF.get(action, ()) else None


def busiest_start(rotations, frames: int, seed: int) -> int:
    """Where a window of ``frames`` starts in a longer take: of the starts a second apart (and the
    last), one of the ``BUSIEST`` whose rotations change most (a take often starts and ends
    standing; a kick is a second of a long take), drawn by the seed."""
    n = len(rotations)
    starts = sorted(set(range(0, n - frames + 1, int(FPS))) | {n - frames})
    change = np.linalg.norm(np.diff(np.asarray(rotations)[:, :22].reshape(n, -1), axis=0), axis=1)
    c = np.concatenate([[0.0], np.cumsum(change)])
    busy = sorted(starts, key=lambda s: -(c[s + frames - 1] - c[s]))[:BUSIEST]
    return busy[random.Random(int(seed)).randrange(len(busy))]


def decoded_provenance(kept: str | None) -> str:
    """Where a motion decoded from codes came from: "generated" (a T5 sample), or the codes of the
    memory clip ``kept``."""
    return "generated" if kept is None else f"generated from the codes of {kept}"


def captured_motion(w: Window, body, betas, ik_refine_iters: int = 10, prompt: str | None = None) -> Motion:
    """The window on the body ``betas`` by its own rotations, feet planted (``planted_retarget``),
    with its provenance."""
    from .retarget import planted_retarget

    out = planted_retarget(w.arrays, body, betas, ik_refine_iters)
    out.prompt = prompt
    out.provenance = w.provenance
    if w.note:
        out.notes.append(w.note)
    if w.looped:
        out.notes.append(f"the captured take plays {(len(w.rotations) - w.looped) / FPS:.1f} s: its own cycle "
                         f"repeats for the remaining {w.looped / FPS:.1f} s")
    if w.cut:
        need, have = (len(w.rotations) + w.cut) / FPS, len(w.rotations) / FPS
        digits = 1 if need - have >= 0.1 else 2   # "take 3.05 s: the 3.00 s asked", never "3.0 ... 3.0"
        out.notes.append(f"the repetitions asked take {need:.{digits}f} s: the {have:.{digits}f} s asked hold fewer of them")
    if w.held:
        out.notes.append(f"the captured take lasts {(len(w.rotations) - w.held) / FPS:.1f} s: {LAST_POSE_HELD} "
                         f"for the remaining {w.held / FPS:.1f} s")
    return out
