"""Text -> body shape + motion, the whole pipeline.

    gen = Generator()                                # default models, OpenBody
    motion = gen.generate("a person jogs forward and waves", shape_text="a tall, heavy-set man")
    save_motion("out.npz", motion)

Steps: prompt checks -> T5 writes [BETA] + motion tokens (constrained decoding, length control)
-> betas from the [BETA] head unless given -> SA-VAE decodes the tokens for those betas ->
joints: the decoded positions' legs, the upper body posed from the decoded rotations
(``decoded_joints``) -> feet planted, IK onto the body with those betas -> ``Motion``.
``redecode(motion, betas)`` re-decodes the same tokens for another body (the shape sliders).
"""
from __future__ import annotations

import dataclasses
from functools import cached_property
from pathlib import Path
from typing import NamedTuple

import numpy as np
import torch

from ..body.load import load_body_model
from ..constants import FPS
from ..data.actions import action_verb
from ..errors import ShapeMoveError
from ..models.constrained_decoding import decode
from ..models.known_texts import read_known
from ..models.savae import load_savae
from ..models.shapemove_t5 import NULL_PROMPT, ShapeMoveT5
from ..models.text_encoder import load_text_encoder
from ..scene.motion_file import Motion
from ..torch_threads import one_torch_thread
from .action_clips import ACTION_CLIPS, UNASKED_SECONDS, action_clips
from .captured_takes import TakePool, Window, action_credit, captured_motion, decoded_provenance
from .one_foot import one_foot_note
from .manner_words import done_as, manner_kept, shown, slower_note, too_slow, unmet_note
from .course_shapes import ACTIONS as COURSE_ACTIONS, unasked_seconds
from .course_takes import course_take
from .course_walk import course_motion
from .decode import decode_features, decode_tokens, redecode
from .gait_steps import MIN_CADENCE, foot_strikes
from .library_takes import captured_window, read_take, window_fit
from .model_bundle import model_files, part_warnings, resolve_model_dir
from .parts import CLAUSE_NEAR, generate_by_parts, is_by_parts, redecode_parts
from .prompts import check_prompt
from .rerank import CandidatePicker
from .retrieval_seeds import seed_prefixes, seeded_count
from .held_pose import held_motion
from .held_repetition import performed
from .on_the_spot import on_the_spot
from ..motion.features import motion_features
from ..plan.part_prompts import LEGS
from ..plan.plan import plan_text, read_plan
from ..plan.reader import without_numbers
from ..plan.segments import MIN_SEGMENT_SECONDS
from ..plan.words import read_words
from .retrieved_candidates import NAMELESS_FLOOR, library_codes, retrieved_codes
from .stop_words import (DISTANCE_PACE, DISTANCE_SECONDS, GOING_SECONDS, OVERSHOOT, STAND_SECONDS, distance_cut,
                         distance_keeps, from_start, standing_after, standing_code, stop_cut, shortened_to)
from .sampling_params import (DEFAULT_GUIDANCE, check_candidates, check_guidance, check_retrieval_first,
                              check_retrieval_prefix, check_retrieved, check_sampling)
from .request import Request
from .slow_action import slowed
from .slow_steps import slow_motion
from .still_take import still_take
from .travel_words import SIDEWAYS_ACTIONS, backward_taken, goes_sideways, other_side
from .hands_asked import hands_wanted
from .typical_pace import (fast_take, leg_ratio, load_typical_speeds, on_performer, slow_take, typical_paced,
                           unplain_take)
from .straight_gait import line_asked, straight_asked
from .take_stop import stop_frame
from .turn_words import turn_motion


LIBRARY_TAKES = 8   # library clips kept read as captured at once (Generator._library_window)


class Choice(NamedTuple):
    """What ``Generator.choose`` kept for one request: a T5 sample's or a memory clip's codes, or a
    captured take's window."""
    codes: list[int] | None       # the codes kept (None: a captured take)
    betas: torch.Tensor           # (10,) the [BETA] head's body
    kept: str | None              # the memory clip whose codes were kept, None for a T5 sample
    window: Window | None         # the captured take kept (captured_takes.py)
    body: np.ndarray              # (10,) the body the motion is made for (``Generator.body_shape``)
    body_source: str              # where that body came from ("[BETA] head", "measurements", ...)
    note: str = ""                # what the motion says of the choice (a manner asked not shown: manner_words.py)

    @property
    def clips(self) -> list[str]:
        """The clip kept ([] for a T5 sample): a memory clip's codes or a captured take (judges leave
        a kept clip's own takes out, ``eval/paraphrase_eval.py``)."""
        return [self.window.clip_id] if self.window is not None else ([self.kept] if self.kept else [])


class Chosen(NamedTuple):
    """What ``Generator.tokens_for`` chose, per request."""
    codes: list[list[int]]        # motion tokens
    betas: torch.Tensor           # (B, 10) the [BETA] head's bodies
    kept: list[str | None]        # the memory clip whose tokens were kept, None for a T5 sample


def _rows(inputs: tuple | None, a: int, b: int) -> tuple | None:
    """Rows a..b-1 of batch-first encoder inputs (rows of one prompt are alike: read once, sliced)."""
    return None if inputs is None else tuple(x[a:b] for x in inputs)


def parse_betas(text: str) -> np.ndarray:
    """'b0,b1,…' (up to 10 numbers; missing ones are 0) -> (10,)"""
    try:
        vals = [float(v) for v in str(text).replace(" ", "").split(",") if v != ""]
    except ValueError:
        raise ShapeMoveError(f"--betas must be comma-separated numbers, got {text!r}") from None
    if not 1 <= len(vals) <= 10 or not np.isfinite(vals).all():
        raise ShapeMoveError(f"--betas takes 1 to 10 finite numbers, got {len(vals)}")
    if max(abs(v) for v in vals) > 5:
        raise ShapeMoveError("--betas values must lie in [-5, 5] (the shape space is ~N(0,1))")
    return np.array(vals + [0.0] * (10 - len(vals)), dtype=np.float32)




def body_from_prompt(body, prompt: str) -> tuple[np.ndarray, str]:
    """(betas, source) when a request has no shape text: the person words of the motion prompt
    ("a man throws a jab", "an old woman sits down": gender, age and build words, never its numbers,
    which describe the motion) set the body; a prompt without them gets the average adult body
    (betas 0, the same for every seed)."""
    from ..body.shape_from_measurements import betas_for_shape_words
    from ..text.shape_words import ShapeWords, parse_shape_words

    words_only = without_numbers(prompt)   # "10 m", "5 seconds"
    try:
        said = parse_shape_words(words_only)
    except ShapeMoveError:  # a prompt is no shape text: what does not read as one is ignored
        return np.zeros(body.num_betas, np.float32), "average adult"
    words = ShapeWords(text=prompt, gender=said.gender, age=said.age, age_implied=said.age_implied,
                       muscle=said.muscle, weight=said.weight,
                       build_words=list(said.build_words), size_words=list(said.size_words), words=[w for w in said.words if not any(c.isdigit() for c in w)])
    if not (words.phenotype() or words.size_words or words.build_words):
        return np.zeros(body.num_betas, np.float32), "average adult"
    try:
        return np.asarray(betas_for_shape_words(body, words), np.float32), "prompt words"
    except ShapeMoveError:
        return np.zeros(body.num_betas, np.float32), "average adult"


class Generator:
    def __init__(self, model_dir=None, body=None, ik_refine_iters: int = 10):
        self.model_dir = resolve_model_dir(model_dir)
        files = model_files(self.model_dir)
        self.body = body if body is not None and not isinstance(body, str) else load_body_model(body)
        self.vae = load_savae(files["savae"], body=self.body)
        self.t5, self.tok = (ShapeMoveT5.load(files["t5"]) if files["t5"].is_dir() else (None, None))

        self.known = read_known(files["t5"]) if self.t5 is not None else None  # training captions + actions
        self.ik_refine_iters = ik_refine_iters
        self.max_codes = int(getattr(self.t5, "info", {}).get("max_codes", 50)) if self.t5 else 50
        trained_null = float(((self.t5.info if self.t5 else {}).get("config") or {}).get("null_share", 0) or 0)
        self.default_guidance = DEFAULT_GUIDANCE if trained_null > 0 else 0.0  # a model without a null prompt: none
        self._tma_file = files.get("tma")
        self._picker = None
        self.library_files: dict[str, Path] = {}   # memory clip id -> the user's file (add_library)
        self._library_takes: dict[str, dict | None] = {}  # library clips read as captured (library_takes.read_take)
        self._library_file = files.get("library")
        self._pool: TakePool | None = None
        self.captured_on = True   # captured takes compete with the samples (captured_takes.py; --no-library: off)

    @property
    def picker(self) -> CandidatePicker | None:
        """The best-of-N chooser on the model folder's TMA (loaded on first use), or None without one."""
        if self._picker is None and self._tma_file is not None and self._tma_file.is_file():
            from ..models.tma_embed import load_tma

            self._picker = CandidatePicker(load_tma(self._tma_file))
        return self._picker

    @property
    def pool(self) -> TakePool | None:
        """The captured takes that compete (the model folder's ``library.npz`` and the user's
        library), loaded on first use; None without the TMA that compares them with a prompt."""
        if self._pool is None and self.picker is not None:
            library = None
            if self._library_file is not None and self._library_file.is_file():
                from ..data.motion_library import MotionLibrary
                from ..model_files import sha256_file, verify_file

                verify_file(self._library_file)
                library = MotionLibrary.load(self._library_file)
            self._pool = TakePool(self.body, library, self._embed_texts, self.ik_refine_iters)
            if library is not None:
                same = library.tma_sha256 and library.tma_sha256 == sha256_file(self._tma_file)
                self._pool.set_vectors(library.vectors if same else None)
        return self._pool

    def _embed_texts(self, texts: list[str]) -> np.ndarray:
        """(N,E) unit TMA text vectors."""
        from ..models.tma_embed import embed_texts

        with one_torch_thread(), torch.no_grad():
            return embed_texts(self.picker.model, self.picker.tok, list(texts))

    def set_captured(self, on: bool) -> None:
        """Captured takes compete with the samples (on, the default) or not (generation only)."""
        self.captured_on = bool(on)

    def _windows(self, r: Request, action: str | None, lo: int, hi: int, side=None,
                 times: int | None = None, competes=None) -> list[Window]:
        """Windows of the captured takes of ``action`` (and the nearest captions) offered for ``r``
        (``captured_takes.TakePool``), cut to the ``times`` repetitions its words count; only those
        that ``competes(window)``, when given."""
        pool = self.pool if self.captured_on else None
        if pool is None or not len(pool):
            return []
        down = self.vae.cfg.downsample
        text = self._embed_texts([r.prompt])[0]
        words = r.reading()
        straight = straight_asked(words) or line_asked(words)   # a gait on a line (straight_gait.py)
        hands = hands_wanted(words, action)   # a gesture's hands as said
        if r.seconds is None:   # the model's length: a take plays whole, at least UNASKED_SECONDS
            return pool.windows(text, action, r.seed, self._length(UNASKED_SECONDS)[0] * down, side, hi * down,
                                times=times, straight=straight, hands=hands, seated=r.seated, competes=competes,
                                repeat=words.again)
        return pool.windows(text, action, r.seed, lo * down, side, times=times, straight=straight, hands=hands,
                            seated=r.seated, competes=competes, repeat=words.again)

    # -- tokens ------------------------------------------------------------------------------
    def _length(self, seconds: float | None) -> tuple[int, int]:
        down = self.vae.cfg.downsample
        if seconds is None:
            return 4, self.max_codes
        if not (0.4 <= seconds <= 60):
            raise ShapeMoveError(f"--seconds must be between 0.4 and 60, got {seconds}")
        n = max(1, int(round(seconds * FPS / down)))
        return n, n

    @torch.no_grad()
    def tokens_for(self, reqs: list[Request], library_as_captured: bool = False) -> Chosen:
        """Each request's chosen motion tokens, the [BETA] head's betas (B, 10) and the memory clip
        whose tokens were kept (None for a T5 sample). ``library_as_captured``: a user's library
        window its codes cannot carry is judged by its captured frames, as ``library_take`` would
        play it (the caller plays it so)."""
        if self.t5 is None:
            raise ShapeMoveError(f"{self.model_dir} has no t5/ model: text-to-motion needs one (train t5)")
        chosen = [self._choose(r, library_as_captured) for r in reqs]
        return Chosen([c.codes for c in chosen], torch.stack([c.betas for c in chosen]), [c.kept for c in chosen])

    @torch.no_grad()
    def choose(self, r: Request, side=None, captured: bool = True, reach: float | None = None,
               body_of: Request | None = None, library_as_captured: bool = True) -> Choice:
        """One request's choice among the T5's samples (and memory clips, as ``tokens_for``) and
        the captured takes of the asked action and nearest captions (``captured_takes.py``), by the
        TMA on the finished motions; ``side``: a named side, the takes mirrored to it. ``captured``
        False: the samples alone (an edit that needs the codes follows: a stop, a distance); ``reach``:
        the distance asked (m), which the samples that get that far compete for; ``body_of``: the
        request whose words give the body (``body_shape``) when ``r`` is a rewording of it (a
        course's plain gait); ``library_as_captured`` False: a user's library clip competes by its
        codes only (a part put together from joint tracks decodes them)."""
        return self._choose(r, library_as_captured, self.captured_on and captured, side, reach, body_of)

    def _choose(self, r: Request, library_as_captured: bool, captured: bool = False, side=None,
                reach: float | None = None, body_of: Request | None = None) -> Choice:
        if self.t5 is None:
            raise ShapeMoveError(f"{self.model_dir} has no t5/ model: text-to-motion needs one (train t5)")
        with one_torch_thread():
            g = torch.Generator().manual_seed(int(r.seed))
            lo, hi = self._length(r.seconds)
            found = self._action_clips(r, lo, hi)
            requested = self._asked(r)
            wanted = self._taken(requested)   # a take of another action than the words ask does not compete
            words = r.reading()
            backward = backward_taken(words, wanted)   # "runs backwards": the data's backward gait is a walk
            asked = backward or wanted
            times = words.count[1] if words.count is not None else None          # "three jumping jacks"
            pool = self.pool if captured else None
            aside = (asked in SIDEWAYS_ACTIONS and pool is not None   # a sidestep that goes to the side
                     and any(pool.sideways(i) for i in range(len(pool)) if pool.actions[i] == asked))
            manners = pool.manners_of(asked, pool.sideways if aside else None) if pool is not None else set()
            manner = manner_kept(words.manner, manners, asked)   # how the takes that compete are done (manner_words.py)

            def competes(w: Window) -> bool:   # of the asked action, at a plain gait's pace, done as asked
                return (action_credit(asked, w.action) is not None
                        and (not asked or done_as(w.manner, manner))
                        and (not aside or goes_sideways(w.features))
                        and not slow_take(w, words, self.typical_speeds, self.body)
                        and not fast_take(w, words, self.typical_speeds, self.body)
                        and not unplain_take(w, words)
                        and not still_take(w, asked, words))

            windows = self._windows(r, asked, lo, hi, side, times, competes) if captured else []
            slower = too_slow(words, asked, manner, windows, self.typical_speeds, self.body)
            if slower:   # "an old man walks quickly": no take done so is quick, a quick plain one is
                manner = manner_kept(None, manners, asked)
                windows = self._windows(r, asked, lo, hi, side, times, competes)
            windows = performed(windows, asked, times, words.again)   # arm circles that stop half way: not when others go on
            if side is None and pool is not None:   # "a cartwheel to the right": a take going left, mirrored
                windows = [pool.mirrored_window(w) if other_side(words.travel, w.features) else w for w in windows]
            for w in windows if backward else []:
                w.note = f"no capture {action_verb(requested)} backwards: a walk backward is played"
            cands, sources, beta = (self._from_action_clips(r, found) if found    # the user's clips: as captured
                                    else self._sampled(r, lo, hi, g, library=not windows, asked=asked))   # takes, or as codes
            if r.seated and any(w.seated for w in windows):   # after a sit: the lie-downs from their sits,
                windows, cands, sources = [w for w in windows if w.seated], [], []   # none that stands up first
            if shown(words.manner, windows):   # "walks proudly": the takes done so, not the samples
                cands, sources = [], []
            note = (slower_note(words.manner, asked) if slower
                    else unmet_note(words.manner, asked, windows) if captured else "")
            note = "; ".join(n for n in (note, one_foot_note(words, asked)) if n)   # "hops on one foot"
            best = 0
            body, body_source = self.body_shape(body_of or r, beta.numpy())
            if reach is not None:   # the distance on the T5's body, which the samples are decoded on
                reach *= leg_ratio(self.body, body, beta.numpy())   # (strides scale with the leg)
            if len(cands) + len(windows) > 1 and self.picker is not None:
                feats = []
                for c, src in zip(cands, sources):
                    fit = self._library_window(src, c) if library_as_captured else None
                    feats.append(decode_features(c, self.vae, beta.numpy()).numpy() if fit is None
                                 else np.asarray(self._library_takes[src]["new_joint_vecs"][fit.lo:fit.hi]))
                bonus = [0.0] * len(cands) + [action_credit(asked, w.action) for w in windows]
                best = self.picker.pick(r.prompt, feats + [w.features for w in windows], bonus, r.words, reach)
            if best >= len(cands):
                return Choice(None, beta, None, windows[best - len(cands)], body, body_source, note)
            return Choice(cands[best], beta, sources[best], None, body, body_source, note)

    @staticmethod
    def _asked(r: Request) -> str | None:
        """The action the request asks for: the planner's reading, else the first its words name
        (``plan.words.Words.actions``, an edited plan's when it has one)."""
        from ..data.actions import specific

        actions = r.reading().actions
        return r.action or (specific(list(actions)) or [None])[0]

    def _taken(self, action: str | None) -> str | None:
        """The action whose captured takes compete for ``action``: itself, or, when no take is of it,
        the more general action it is a form of that has takes (``actions.GENERIC_OF``: a hop is a
        jump, ballet a dance)."""
        from ..data.actions import GENERIC_OF

        pool = self.pool if self.captured_on else None
        if action is None or pool is None or action in pool.actions:
            return action
        return next((g for g in GENERIC_OF.get(action, ()) if g in pool.actions), action)

    def _sampled(self, r: Request, lo: int, hi: int, g: torch.Generator, library: bool = True,
                 asked: str | None = None):
        """(candidate codes, their memory clip or None, betas): best-of-N's T5 samples (some seeded
        by retrieved clips) and the retrieved clips nearest by caption (``library``: the user's
        library clips' codes among them); when the words ask for an action (``asked``), a retrieved
        clip labelled with another one does not compete, as a captured take of it would not
        (``captured_takes.action_credit``: "an old man sits down slowly" finds an elderly walk by
        its caption)."""
        n = r.candidates if r.temperature > 0 and self.picker is not None else 1
        seeds = self._retrieval_seeds(r, n)
        s = self.default_guidance if r.guidance is None else r.guidance
        inputs = self.t5.inputs_for(self.tok, [r.prompt] * n, [r.shape_text] * n)  # read once for all rows
        null = self.t5.inputs_for(self.tok, [NULL_PROMPT] * n, [r.shape_text] * n) if s > 0 else None
        cands, beta = [], None
        for a, b, prefix in ((0, n - len(seeds), None), (n - len(seeds), n, seeds)):
            if a == b:
                continue
            out = decode(self.t5, _rows(inputs, a, b), lo, hi, temperature=r.temperature, top_k=r.top_k,
                         generator=g, guidance=s, null_inputs=_rows(null, a, b), prefix_codes=prefix)
            cands += out.codes
            beta = out.betas[0] if beta is None else beta  # [BETA] precedes the codes: one body for all
        sources = [None] * len(cands)
        if n > 1:  # real clips nearest by caption compete with the samples, or replace them
            named = bool(r.reading().actions)
            found = [f for f in self._retrieved(r, lo, hi, library)
                     if action_credit(asked, self.t5.memory.main_action(f[0])) is not None
                     and (named or f[1] >= NAMELESS_FLOOR or f[0] in self.library_files)]   # no action named:
            # only a caption that says it, or the user's own clip (its own floor: retrieved_candidates.LIBRARY_FLOOR)
            if found and r.retrieval_first is not None and found[0][1] >= r.retrieval_first:
                cands, sources = [], []
            for cid, _, c in found:
                cands.append(c)
                sources.append(cid)
        return cands, sources, beta

    def _action_clips(self, r: Request, lo: int, hi: int) -> list[tuple[str, list[int]]]:
        """The memory's clips of the action the request names (``action_clips.py``), when it names
        one, the model folder has a memory and retrieval is on."""
        if not r.action or self.t5.memory is None or not self.t5.memory_enabled:
            return []
        if r.seconds is None:  # the model decides: no shorter than UNASKED_SECONDS of captured motion
            lo = max(lo, min(hi, self._length(UNASKED_SECONDS)[0]))
        return action_clips(self.t5.memory, self._text_encoder(), r.prompt, r.action, ACTION_CLIPS, r.seed, lo, hi)

    def _from_action_clips(self, r: Request, found):
        """(candidate codes, their clips, betas) from clips of the asked-for action."""
        return [c for _, c in found], [cid for cid, _ in found], self.predicted_betas(r.prompt, r.shape_text)

    @torch.no_grad()
    def predicted_betas(self, prompt: str, shape_text: str | None) -> torch.Tensor:
        """(10,) the [BETA] head's betas for a prompt, without sampling any codes (the same state
        a sample's [BETA] is read from)."""
        with one_torch_thread():
            return self.t5.predict_betas(self.t5.inputs_for(self.tok, [prompt], [shape_text]))[0]

    def _retrieved(self, r: Request, lo: int, hi: int, library: bool = True) -> list[tuple[str, float, list[int]]]:
        """(clip id, caption similarity, codes) of the memory's clips nearest to the prompt (``retrieved_candidates.py``),
        when the model folder has a memory and retrieval is on."""
        if not r.retrieved or self.t5.memory is None or not self.t5.memory_enabled:
            return []
        found = retrieved_codes(self.t5.memory, self._text_encoder(), r.prompt, r.retrieved, lo, hi)
        if not library:
            return found
        return found + library_codes(self.t5.memory, self._text_encoder(), r.prompt, self.library_files, found, lo, hi)

    def offers_library(self, r: Request) -> bool:
        """Whether a clip of the user's library competes for ``r`` at its length (``retrieved_candidates``):
        a caption comparison, no sampling."""
        if not self.library_files:
            return False
        return any(cid in self.library_files for cid, _, _ in self._retrieved(r, *self._length(r.seconds)))

    def _retrieval_seeds(self, r: Request, n: int) -> list[list[int]]:
        """Prefixes for the seeded share of ``n`` candidates (``retrieval_seeds.py``): only for a model
        that reads retrieved clips, with retrieval on, and a best-of-N to choose among them."""
        if n < 2 or not r.retrieval_prefix or not self.reads_memory or not self.t5.memory_enabled:
            return []
        return seed_prefixes(self.t5.memory, self.tok, r.prompt, seeded_count(n), r.retrieval_prefix)

    def course_seconds(self, words) -> float | None:
        """The length a course or a distance the words name gets when none is asked: once round, or
        the distance gone and a stop, at the typical pace of its gait (``course_shapes.unasked_seconds``
        on the model folder's table)."""
        return unasked_seconds(words, self.typical_speeds)

    @staticmethod
    def asks_course(words, check, edited: bool = False) -> str | None:
        """The course a prompt asks to walk (``course_shapes.COURSES``), or None: the plan's
        (``words``: a ``plan.words.Words``; ``edited``: the user's plan, taken as it is), or by its
        nearest training caption ("pace around in a loop"), read from its ``check_text`` (None: no
        known captions) as ``parts.clause_classifier`` reads a clause's."""
        named = words.course
        if edited or named is not None or check is None or check.similarity < CLAUSE_NEAR:
            return named
        return check.nearest_action if check.nearest_action in COURSE_ACTIONS else None

    # -- what the model knows ----------------------------------------------------------------
    @property
    def known_actions(self) -> list[str]:
        """The actions of the model's training data, most frequent first ([] for older models)."""
        return self.known.action_names if self.known is not None else []

    # -- retrieval memory ----------------------------------------------------------------------
    @property
    def reads_memory(self) -> bool:
        """Whether the model's decoder reads retrieved clips (``models/motion_memory.py``)."""
        return self.t5 is not None and self.t5.memory_k > 0

    def set_retrieval(self, on: bool) -> None:
        """Turn the retrieved clips on or off (off: the decoder reads the prompt alone)."""
        if self.t5 is not None:
            self.t5.memory_enabled = bool(on)

    def add_library(self, folder, progress=None) -> int:
        """Add a folder of the user's own motions (the Library panel's folder: motion .npz, BVH/AMC
        or a built dataset, each with a caption) to the retrieval memory, without retraining: their
        SA-VAE tokens become clips the decoder can read (a model with ``memory_k``) and candidates
        retrieved by caption (``retrieved_candidates.py``). Returns the number of clips added."""
        from ..search.motion_search import library_clips

        if self.t5 is None:
            raise ShapeMoveError(f"{self.model_dir} has no t5/ model: a motion library is retrieved by the text model")
        if self.t5.memory is None:  # a model without a memory: the library alone is retrieved
            from ..models.motion_memory import MotionMemory

            self.t5.memory = MotionMemory.empty()
        ids, captions, feats, files = library_clips(folder, progress=progress)
        tokens = []
        down = self.vae.cfg.downsample
        with torch.no_grad(), one_torch_thread():
            for f in feats:
                n = (len(f) // down) * down
                idx = self.vae.encode_tokens(self.vae.normalize(torch.as_tensor(f[:n], dtype=torch.float32)[None]))
                tokens.append(idx[0].numpy())
        self.t5.memory.add_clips([f"library:{i}" for i in ids], [[c] for c in captions], tokens, self.tok)
        self._library_takes.clear()
        self.library_files.update({f"library:{i}": Path(f) for i, f in zip(ids, files)})
        if self.pool is not None:   # and as captured takes, beside the built-in library's (captured_takes.py)
            self.pool.add_files([f"library:{i}" for i in ids], [Path(f) for f in files], list(captions))
        return len(ids)

    def _library_window(self, clip: str | None, codes: list[int]):
        """``library_takes.window_fit`` of a window of the user's library clip ``clip`` (its file read
        once and kept, ``LIBRARY_TAKES`` at a time); None for a clip not of the library or a window
        its codes carry."""
        path = self.library_files.get(clip) if clip else None
        if path is None or self.t5 is None or self.t5.memory is None or clip not in self.t5.memory.clip_ids:
            return None
        if clip not in self._library_takes:
            if len(self._library_takes) >= LIBRARY_TAKES:
                self._library_takes.pop(next(iter(self._library_takes)))
            try:
                self._library_takes[clip] = read_take(path, self.body, self.ik_refine_iters)
            except ShapeMoveError:   # a file whose joints the builder cannot read: its codes are played
                self._library_takes[clip] = None
        if self._library_takes[clip] is None:
            return None
        clip_codes = self.t5.memory.clip_tokens[self.t5.memory.clip_ids.index(clip)]
        return window_fit(self._library_takes[clip], clip_codes, codes, self.vae)

    def library_take(self, clip: str | None, codes: list[int], betas, prompt: str | None = None) -> Motion | None:
        """The user's library clip ``clip`` kept for a prompt (its window ``codes``), played from its
        own file when its codes cannot carry it (``library_takes.captured_window``); None for
        anything else (the decoded codes are played)."""
        with one_torch_thread():
            fit = self._library_window(clip, codes)
            if fit is None:
                return None
            motion = captured_window(self._library_takes[clip], fit, self.body, betas, self.library_files[clip].name,
                                     self.ik_refine_iters)
        motion.prompt = prompt
        return motion

    def chosen_motion(self, c: Choice, betas, prompt: str | None = None) -> Motion:
        """The finished motion of a ``Choice`` on the body ``betas``, with its provenance: a captured
        take moved by its own rotations (``captured_takes.captured_motion``), a library clip the
        codes miss played as captured (``library_take``), or the codes decoded."""
        if c.window is not None:
            with one_torch_thread():
                m = captured_motion(c.window, self.body, betas, self.ik_refine_iters, prompt)
        else:
            m = self.library_take(c.kept, c.codes, betas, prompt)
            if m is not None:
                m.provenance = f"captured: {self.library_files[c.kept].name} (your library)"
            else:
                m = self.decode_motion(c.codes, betas, prompt=prompt)
                m.provenance = decoded_provenance(c.kept)
        if c.note:
            m.notes.append(c.note)
        return m

    def _text_encoder(self):
        if self.t5 is not None and self.t5.encoder_kind == "minilm":
            return self.tok

        return load_text_encoder()

    def check_text(self, prompt: str, what: str = "prompt"):
        """Refuse text the model cannot read (mostly unknown characters / <unk>); return the
        ``PromptCheck`` of a prompt against the training captions (None for older models): its
        similarity, nearest known actions and a warning when it is far from all of them."""
        if self.t5 is None:
            return None
        if self.t5.encoder_kind == "minilm" or self.known is not None:
            unknown = self._text_encoder().unknown_share(prompt)
        else:  # a T5 on its own sentencepiece vocabulary
            ids = [i for i in self.tok(prompt).input_ids if i != self.tok.eos_token_id]
            unknown = sum(i == self.tok.unk_token_id for i in ids) / max(1, len(ids))
        if unknown > 0.5:
            raise ShapeMoveError(f"the {what} {prompt!r} is mostly characters the text encoder does not know "
                                 f"({100 * unknown:.0f}% unknown); describe it in English words")
        if what != "prompt" or self.known is None:
            return None
        return self.known.check(prompt, self._text_encoder())

    # -- motion ------------------------------------------------------------------------------
    def decode_motion(self, codes: list[int], betas: np.ndarray, prompt: str | None = None) -> Motion:
        """Tokens + body shape -> Motion on the body model (SA-VAE decode, joints, IK)."""
        return decode_tokens(codes, self.vae, self.body, betas, self.ik_refine_iters, prompt=prompt)

    def generate(self, prompt: str, shape_text: str | None = None, betas=None, seconds: float | None = None,
                 seed: int = 0, temperature: float = 1.0, top_k: int | None = 50) -> Motion:
        return self.generate_batch([Request(prompt, shape_text, betas, seconds, seed, temperature, top_k)])[0]

    def generate_batch(self, reqs: list[Request], progress=None, cancel=None) -> list[Motion]:
        for r in reqs:
            r.prompt = check_prompt(r.prompt)
            r.shape_text = check_prompt(r.shape_text, "shape text", allow_empty=True) or None
            r.seed, r.temperature, r.top_k = check_sampling(r.seed, r.temperature, r.top_k)
            r.candidates = check_candidates(r.candidates)
            r.guidance = check_guidance(r.guidance)
            r.retrieval_prefix = check_retrieval_prefix(r.retrieval_prefix)
            r.retrieved = check_retrieved(r.retrieved)
            r.retrieval_first = check_retrieval_first(r.retrieval_first)
        checks = []
        for r in reqs:  # every text checked before any generation
            with one_torch_thread():
                checks.append(self.check_text(r.prompt))
                if r.shape_text:
                    self.check_text(r.shape_text, "shape text")
            if r.shape_text and r.betas is None and r.shape_from == "auto":
                from ..body.shape_from_measurements import betas_for_shape_text

                betas_for_shape_text(self.body, r.shape_text)  # contradictions, impossible bodies: refused first
            elif r.shape_text and r.betas is None and self.t5 is not None:   # the head's reading, refused first too
                with one_torch_thread(), torch.no_grad():
                    self.t5.predict_betas(self.t5.inputs_for(self.tok, [r.prompt], [r.shape_text]))
        out = []
        for i, (r, check) in enumerate(zip(reqs, checks)):
            if cancel is not None and cancel():
                break
            plan = (r.plan or read_plan(r.prompt)) if r.by_parts else None   # "walks forward, then sits down"
            if plan is not None and plan.is_sequence:
                motion = self.planned_sequence(r, plan)
                motion.plan = plan_text(plan)
                motion.warnings = [check.warning] if check is not None and check.warning else []
                motion.prompt_check = check
                out.append(motion)
                if progress is not None:
                    progress((i + 1) / len(reqs), r.prompt)
                continue
            words = plan.segments[0].words if plan is not None else None   # what the words ask (plan/words.py)
            edited = r.plan is not None
            stop = (words.gait_text, words.steps) if words is not None and words.stop else None   # "takes three steps"
            metres = words.distance_m if stop else None      # "walks 3 metres": that far, then stands
            asked = dataclasses.replace(r, prompt=stop[0], seconds=r.seconds if r.seconds or not metres else
                                        min(DISTANCE_SECONDS, metres / DISTANCE_PACE + 1.0)) if stop else r
            if stop and stop[1] is None and not metres and asked.seconds is None and words.seconds is None:
                asked = dataclasses.replace(asked, seconds=2 * GOING_SECONDS)   # "jogs and stops": going a while (cut at half)
            asked = dataclasses.replace(asked, plan=None, words=None)
            if asked.seconds is None and words is not None and words.seconds is not None:   # "for ten seconds"
                asked = dataclasses.replace(asked, seconds=words.seconds)
            if asked.seconds is None and words is not None and words.course is not None:   # once round
                asked = dataclasses.replace(asked, seconds=self.course_seconds(words))   # (course_walk.py)
            by_parts = words is not None and (words.parts is not None or words.side is not None or not edited)
            standing = words is not None and words.stand_still and self.rest_code is not None
            motion = self.standing(dataclasses.replace(r, seconds=asked.seconds)) if standing else \
                generate_by_parts(self, asked, words if edited else None, captured=stop is None) if by_parts else None
            came_from = motion.provenance if motion is not None else None   # kept through the edits below
            if motion is not None and stop is not None:
                motion.prompt = r.prompt
                motion = self.stopped(motion, stop[1], r.seconds, metres)   # both parts stop (stop_words.py)
            if motion is not None and words.parts is not None:   # the legs' gait at its typical pace, and
                legs = read_words(words.parts.legs_prompt)          # "walks slowly, waving": both parts slower
                motion = typical_paced(motion, self.body, legs, self.typical_speeds, self.ik_refine_iters, course=False)
                motion = slow_motion(motion, self.body, words, self.ik_refine_iters)   # (slow_steps.py)
                motion = slowed(motion, self.body, words, r.seconds is not None, self.ik_refine_iters)   # slow_action.py
            course = self.asks_course(words, check, edited) if words is not None else None   # course_walk.py
            if motion is None:  # one action, no side named: the motion as the model writes it
                sampled = asked if course is None else dataclasses.replace(asked, prompt=read_words(asked.prompt).straight_text)
                sampled = dataclasses.replace(sampled, words=words) if edited else sampled
                # samples and captured takes, one choice (captured_takes.py); a stop or a distance is cut
                # in the codes (stop_words.py) and a turn is given back to the decoded motion, so those are
                # asked of the samples alone; a course bends a plain gait, a captured one made straight
                # (straight_gait.py) as read from the straight words (an edited plan's course: samples alone)
                turn = words.turn if words is not None else None   # turn_words.py: given back after
                captured = stop is None and turn is None and (course is None or not edited)
                own = (course_take(self, asked, words, course, r.seconds is None and words.seconds is None, r)
                       if course is not None and captured and not r.whole_course else None)   # course_takes.py
                choice = own or self.choose(sampled, captured=captured, reach=metres, body_of=r)
                betas, source = choice.body, choice.body_source
                motion = self.chosen_motion(choice, betas, r.prompt)
                came_from = motion.provenance
                if stop is not None:   # stop_words.py: cut, then stand; take_stop.py where the codes slide
                    motion = self.stopped(motion, stop[1], r.seconds, metres)
                    taken = self._stopped_take(sampled, choice, motion, stop[1], metres, r.seconds)
                    if taken is not None:
                        choice, motion = taken, self.chosen_motion(taken, betas, r.prompt)
                        came_from = motion.provenance
                motion.shape_source = source
                motion.retrieved_clips = choice.clips
                self._say_if_short(motion, choice.kept, r.seconds)
                if words is not None:  # its gait's pace, slowed when asked, then (the codec does not carry
                    # turning) a course or a turn the words name given back on the paced track
                    motion = typical_paced(motion, self.body, words, self.typical_speeds, self.ik_refine_iters)
                    motion = slow_motion(motion, self.body, words, self.ik_refine_iters)      # slow_steps.py
                    motion = slowed(motion, self.body, words, r.seconds is not None, self.ik_refine_iters)   # slow_action.py
                    motion = (course_motion(motion, self.body, course, words.course_right, self.ik_refine_iters, r.whole_course)
                              if course is not None and own is None else                          # course_walk.py
                              turn_motion(motion, self.body, turn, self.ik_refine_iters))         # turn_words.py
            if words is not None and words.arms_held and words.gestures_only and words.parts is None:
                motion = held_motion(motion, self.body, self.ik_refine_iters)   # "stands with her arms raised"
            if words is not None and words.held_low and words.parts is None:   # "squats and holds it"
                motion = held_motion(motion, self.body, self.ik_refine_iters, low=True)
            if words is not None:   # "jogs in place", "hops on the spot": the data's gaits and hops travel
                motion = on_the_spot(motion, self.body, words.travel.in_place, self.ik_refine_iters)   # on_the_spot.py
            motion.plan = plan_text(plan) if plan is not None else None
            motion.provenance = motion.provenance or came_from or "generated"
            motion.warnings = [check.warning] if check is not None and check.warning else []
            if r.candidates > 1 and r.temperature > 0:  # best-of-N wanted: say when the model cannot pick
                motion.warnings += part_warnings(self.model_dir)
            motion.prompt_check = check
            out.append(motion)
            if progress is not None:
                progress((i + 1) / len(reqs), r.prompt)
        return out

    def standing(self, r: Request) -> Motion:
        """"a person stands still", "she waits": no caption stands still, so nothing sampled does;
        the model's standing code (``stop_words.standing_code``) for the length asked
        (``STAND_SECONDS`` when none), decoded on the request's body."""
        n = self._length(r.seconds)[0] if r.seconds is not None else max(1, round(STAND_SECONDS * FPS / self.vae.cfg.downsample))
        with one_torch_thread():
            betas, source = self.body_shape(r, self.predicted_betas(r.prompt, r.shape_text).numpy())
        motion = self.decode_motion([self.rest_code] * n, betas, prompt=r.prompt)
        motion.shape_source, motion.provenance = source, "generated"
        return motion

    def planned_sequence(self, r: Request, plan) -> Motion:
        """A prompt of segments in order (``plan.segments.Plan``: "walks forward, then sits down") made
        as a timeline of its segments (``sequence.generate_sequence``: where captured takes compete,
        each segment's own choice among samples and takes), each its share of ``r.seconds``
        (``Plan.lengths``), one body for all."""
        from .sequence import generate_sequence

        lengths = plan.lengths(r.seconds, self.course_seconds)   # a course's segment: once round
        if min(lengths) < MIN_SEGMENT_SECONDS:
            raise ShapeMoveError(f"{r.prompt!r} is {len(lengths)} motions in order: {r.seconds:g} s gives each "
                                 f"{min(lengths):.2f} s, under the {MIN_SEGMENT_SECONDS:g} s one needs; ask for more seconds")
        # an edited plan's readings are acted on as they are; a read plan's where the plan reads a segment
        # otherwise than its words alone would ("walks forward, then walks back": the return turns)
        own = [r.plan is not None or s.words != read_words(s.text) for s in plan.segments]
        motion = generate_sequence(self, [(s.text, sec) for s, sec in zip(plan.segments, lengths)], r.shape_text,
                                   r.betas, r.seed, r.temperature, r.top_k, r.candidates, r.guidance, by_parts=True,
                                   readings=[s.words if o else None for s, o in zip(plan.segments, own)]
                                   if any(own) else None)
        motion.prompt = r.prompt
        return motion

    @cached_property
    def typical_speeds(self) -> dict[str, float]:
        """{gait: typical speed on the average body} of the model folder's table (``typical_pace.py``)."""
        return load_typical_speeds(self.model_dir)

    @cached_property
    def rest_code(self) -> int | None:
        """The code that decodes to standing still (``stop_words.standing_code``, found once); None
        for a model without a memory or such a code."""
        return standing_code(self.t5.memory if self.t5 is not None else None, self.vae)

    def _stopped_take(self, r: Request, choice: Choice, motion: Motion, steps: int | None, metres: float | None,
                      seconds: float | None) -> Choice | None:
        """Where the chosen codes of a gait asked to stop (``r``: its words without the stop), cut where
        they stop (``motion``), do not step (fewer than ``steps`` strikes, or ``gait_steps.MIN_CADENCE``
        a second, before the standing code and over its first code, where the last step lands: a
        backward walk's slide), the captured take of that gait the TMA finds nearest, cut where the
        words stop it and held (``take_stop.py``); ``seconds``: the length asked (None: the cut and
        ``STAND_SECONDS``). None where the codes step, or no take of the gait gets that far."""
        words = r.reading()
        gait = words.actions[0] if len(words.actions) == 1 else None
        if choice.window is not None or gait not in LEGS or self.pool is None or not self.captured_on:
            return None
        codes = [int(c) for c in motion.tokens] if motion.tokens is not None else []
        kept = len(codes)
        while kept and codes[kept - 1] == self.rest_code:
            kept -= 1
        feats = motion_features(motion)[: (kept + 1) * self.vae.cfg.downsample]   # the last step lands on
        if len(feats) and foot_strikes(feats) >= (steps if steps else MIN_CADENCE * len(feats) / FPS):
            return None
        lo, hi = self._length(r.seconds)
        stand = round(STAND_SECONDS * FPS)
        manner = manner_kept(words.manner, self.pool.manners_of(gait), gait)   # done as asked, else plainly (manner_words.py)
        held = []
        for w in self._windows(r, gait, lo, hi, competes=lambda w: w.action == gait and done_as(w.manner, manner)):
            going = round(GOING_SECONDS * FPS) if seconds is None else len(w.root) // 2
            there = None if metres is None else on_performer(metres, w, self.body, choice.body)   # the body asked's
            k = stop_frame(w.contacts, w.root, steps, there, going)
            if k is not None:
                frames = k + stand if seconds is None else max(k, round(seconds * FPS))
                held.append(self.pool.held_from(w, k, frames, f"stopped at {k / FPS:.1f} s, then standing"))
        if not held:
            return None
        best = self.picker.pick(r.prompt, [w.features for w in held], words=words)
        return choice._replace(codes=None, kept=None, window=held[best])

    def stopped(self, motion: Motion, steps: int | None, seconds: float | None = None,
                metres: float | None = None) -> Motion:
        """``motion`` (decoded from its tokens) cut after ``steps`` foot strikes (None: half its
        length), or where it is ``metres`` from its start (of that code and the next, the one that
        stands nearest the distance once decoded again), and standing still for the rest of
        ``seconds`` (None: the length was the model's, ``STAND_SECONDS`` of standing)
        (``stop_words.py``), decoded again as it was made (a motion made by part: its arms' tokens
        cut at the same code, mirrors kept); unchanged when the model has no standing code or the
        gait strikes fewer times; with a note when it does not get as far as asked."""
        rest = self.rest_code
        if rest is None or motion.tokens is None or motion.planted_take:   # a take plays its own rotations
            return motion
        down = self.vae.cfg.downsample
        stand = None if seconds is not None else max(1, round(STAND_SECONDS * FPS / down))
        n = len(motion.tokens)
        if metres is None:
            keep = stop_cut(motion.contacts, steps, n, down)
            keeps = [] if keep is None else [keep]
        else:
            keep = distance_cut(motion.joints, metres, n, down)
            keeps = [] if keep is None else distance_keeps(keep, n)
            if keep is None:
                gone = float(from_start(motion.joints)[-1])
                motion.notes.append(f"went {gone:.1f} m of the {metres:.1f} m asked in {motion.num_frames / motion.fps:.1f} s: "
                                    "ask for more seconds")
        best, off = motion, np.inf
        for k in keeps:
            codes = standing_after(motion.tokens, k, rest, stand)
            if codes == [int(c) for c in motion.tokens]:
                continue
            arms = motion.arms_tokens
            cut = dataclasses.replace(motion, tokens=np.asarray(codes, np.int32), arms_tokens=(
                None if arms is None else np.asarray(standing_after(arms, k, rest, stand), np.int32)))
            out = self._redecoded(cut, motion.betas)
            gone = float(from_start(out.joints)[-1])
            if metres is None or abs(gone - metres) < off:
                best, off = out, (0.0 if metres is None else abs(gone - metres))
        if best is not motion:
            best.shape_source, best.retrieved_clips = motion.shape_source, list(motion.retrieved_clips)
            best.part_prompts = motion.part_prompts
            if metres is not None:   # past the mark by more than the cut's grain: shorter strides
                best = shortened_to(best, self.body, metres, self.ik_refine_iters)
        gone = float(from_start(best.joints)[-1]) if metres is not None else None
        if keep is not None and gone is not None and gone < metres * (1 - OVERSHOOT):   # short, within the slack
            best.notes.append(f"went {gone:.1f} m of the {metres:.1f} m asked in {best.num_frames / best.fps:.1f} s: "
                              "ask for more seconds")
        return best

    def _say_if_short(self, motion: Motion, clip: str | None, seconds: float | None) -> None:
        """A note when a kept library clip, shorter than the length asked, was played whole
        (``retrieved_candidates.LIBRARY_SHORTEST``)."""
        if clip not in self.library_files or seconds is None:
            return
        if motion.num_frames < self._length(seconds)[0] * self.vae.cfg.downsample:
            motion.notes.append(f"your library clip {self.library_files[clip].name} lasts "
                                f"{motion.num_frames / motion.fps:.1f} s: played whole, shorter than the "
                                f"{seconds:g} s asked")

    def body_shape(self, r: Request, predicted: np.ndarray) -> tuple[np.ndarray, str]:
        """The betas for a request and where they came from: explicit betas; else, when the shape
        text states measurements or size words ("190 cm tall", "tall, heavy-set"), a body fitted to
        those numbers (milliseconds: girths from the body's precomputed regression); else the
        T5's [BETA] head. Numbers that no body has ("5000 cm tall", "waist 0 cm", "-170 cm") are
        refused with a ShapeMoveError, never replaced by a guess."""
        from ..body.shape_from_measurements import betas_for_shape_text

        if r.betas is not None:
            return np.asarray(r.betas, np.float32), "given"
        if r.shape_text and r.shape_from == "auto":
            betas = betas_for_shape_text(self.body, r.shape_text)  # None: free text, the model's reading of it
            if betas is not None:  # shape words (phenotype sliders) and stated numbers met on the mesh
                return np.asarray(betas, np.float32), "measurements"
        if not (r.shape_text and r.shape_text.strip()) and r.shape_from == "auto":
            return body_from_prompt(self.body, r.prompt)
        return np.asarray(predicted, np.float32), "[BETA] head"

    def head_reading(self, prompt: str, shape_text: str | None) -> str | None:
        """What the [BETA] head's unit reader made of the shape text's numbers ("6 ft 2 in = 188.0
        cm; 200 lb = 90.7 kg"), None for a head without one or a text that states no size."""
        units = getattr(getattr(self.t5, "beta_head", None), "units", None)
        if units is None or not (shape_text and shape_text.strip()):
            return None
        from ..models.number_units import describe

        with one_torch_thread(), torch.no_grad():
            states, mask, numbers = self.t5.head_text(self.t5.inputs_for(self.tok, [prompt], [shape_text]))
            said = describe(units.read_units(states * mask[..., None], numbers)[0])
        return said or None

    def redecode(self, motion: Motion, betas) -> Motion:
        """The same tokens on another body (``decode.redecode``; a motion made by body part is
        composed and mirrored again, ``parts.redecode_parts``; a timeline assembled again,
        ``sequence.redecode_timeline``); a take played by its own rotations (no tokens, measured
        contacts) is planted again on the new body (``retarget.replant``), a loop likewise, as a
        loop (``loop.replant_loop``). A motion held in place (``in_place.py``) is held in place again."""
        out = self._redecoded(motion, betas)
        out.plan = out.plan or motion.plan   # the plan it was made from
        if motion.held_in_place and not out.held_in_place:
            from .in_place import in_place

            out = in_place(out)
        return out

    def _redecoded(self, motion: Motion, betas) -> Motion:
        if motion.planted_loop:   # a loop has no tokens: moved by its rotations, as a take
            from .loop import replant_loop

            return replant_loop(motion, self.body, betas, self.ik_refine_iters)
        if motion.planted_take:
            from .retarget import replant

            return replant(motion, self.body, betas, self.ik_refine_iters)
        if motion.segment_bounds is not None and motion.tokens is not None:   # a timeline, assembled again
            from .sequence import redecode_timeline

            return redecode_timeline(self, motion, betas)
        if is_by_parts(motion):
            return redecode_parts(motion, self.vae, self.body, betas, self.ik_refine_iters)
        return redecode(motion, self.vae, self.body, betas, self.ik_refine_iters)
