"""Generation by body part: a prompt of two things at once, or one that names a side.

    motion = generate_by_parts(gen, request)     # None: the prompt asks nothing of the parts
    motion = redecode_parts(motion, vae, body, betas)

The plan reads the prompt (``plan/part_prompts.plan_parts``, ``plan/words.py``). Two things at once
("jogs along, waving"): each part is its own choice among the T5's samples and the captured takes
of its action (``Generator.choose``; the legs first, the arms then for as long as the legs last).
Each becomes a joint track on the body (``part_of``): a captured take moved by its own rotations,
or the SA-VAE's decoding of the codes, mirrored when the arms name a side that is not the one that
moves most (a take is mirrored when offered). The arms are put on the legs track's chest
(``part_compose.compose_arms``) and the whole is planted on the legs track's foot contacts
(``decode.motion_from_joints``; a captured legs take's measured contacts as they are). A motion
with a captured part keeps no tokens and says where each part came from ("legs: captured: ...;
arms: generated"); another body plants it again by its rotations (``retarget.replant``). A
single action naming a side ("kick with the left foot") is generated as usual and mirrored when the
other side moves most in the planted motion (planting, the foot roll above all, changes how far a
foot travels).

A motion of two sets of codes keeps what re-decoding needs: ``tokens`` (the legs, or the whole
motion), ``arms_tokens`` and the two mirror flags; ``features`` are those of the planted motion,
computed as the dataset builder computes a clip's (``motion.features.posed_features``: the posed
joints, their IK rotations, the planted contacts), so every later reader of the features (the part
judge, the TMA) sees what the rig plays.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..constants import FPS
from ..errors import ShapeMoveError
from ..motion.features import motion_features
from ..scene.motion_file import Motion
from .captured_takes import decoded_provenance
from ..plan.part_prompts import PartPlan, plan_parts
from ..plan.words import read_words
from .course_shapes import ACTIONS as COURSE_ACTIONS
from .course_walk import course_motion, course_note, on_course
from .decode import motion_from_joints
from .part_compose import compose_arms, mirror_track, needs_mirror
from .retarget import shaped_take
from .held_pose import held_from_peak, held_note
from .track import Track, decoded_track, fitted


def _mirrored(track: Track) -> Track:
    return Track(*mirror_track(track.joints, track.contacts))


def _track(codes, vae, body, betas, mirrored: bool) -> Track:
    track, _ = decoded_track([int(c) for c in codes], vae, body, betas)
    return _mirrored(track) if mirrored else track


def _side_fixed(codes, vae, body, betas, side: tuple[str, str] | None) -> tuple[Track, bool]:
    """The decoded track, mirrored when it names a side that moves less than the other."""
    track = _track(codes, vae, body, betas, False)
    if side is not None and needs_mirror(track.joints, *side):
        return _mirrored(track), True
    return track, False


def assemble(body, betas, legs: Track, arms: Track | None, prompt: str | None, ik_refine_iters: int,
             known_contacts: bool = False, **extra) -> Motion:
    """The planted Motion of a legs track (and the arms of an arms track, when given);
    ``known_contacts``: the legs are a captured take's, their contacts measured (planted as they are,
    no smoothing)."""
    joints = compose_arms(legs.joints, arms.joints) if arms is not None else legs.joints
    m = motion_from_joints(body, betas, joints, legs.contacts, ik_refine_iters, prompt=prompt,
                           known_contacts=known_contacts, **({"smooth": 0.0} if known_contacts else {}), **extra)
    m.features = motion_features(m)  # as the builder's clips
    return m


@dataclasses.dataclass
class Part:
    """One part's chosen motion as a joint track on the body, and what the Motion keeps of it."""
    track: Track
    codes: list[int] | None   # None: a captured take, played by its own rotations
    mirrored: bool
    provenance: str


def part_of(gen, choice, betas, side: tuple[str, str] | None = None) -> Part:
    """The joint track of one part's ``Generator.choose`` on the body ``betas``: a captured take's
    window posed by its own rotations (``retarget.shaped_take``; its measured contacts; already
    mirrored to ``side``), or the codes decoded, mirrored when ``side`` names the side that moves
    less."""
    w = choice.window
    if w is not None:
        track = Track(shaped_take(w.arrays, gen.body, betas, gen.ik_refine_iters), np.asarray(w.contacts, np.uint8))
        return Part(track, None, bool(w.mirrored), w.provenance)
    track, flipped = _side_fixed(choice.codes, gen.vae, gen.body, betas, side) if side is not None else \
        (_track(choice.codes, gen.vae, gen.body, betas, False), False)
    return Part(track, [int(c) for c in choice.codes], flipped, decoded_provenance(choice.kept))


CLAUSE_NEAR = 0.5   # MiniLM cosine from which a clause takes the action of its nearest training caption


def clause_classifier(gen):
    """``classify(clauses)`` for ``plan_parts``: each clause's action is that of the nearest
    training caption the model knows (``known_texts``), when it is at least ``CLAUSE_NEAR``
    similar; None without known texts."""
    known = getattr(gen, "known", None)
    if known is None:
        return None
    encoder = gen._text_encoder()

    def classify(texts: list[str]) -> list[str | None]:
        sims = encoder.embed(list(texts)) @ known.vectors.T
        best = sims.argmax(1).tolist()
        return [known.caption_actions[b] or None if float(sims[i, b]) >= CLAUSE_NEAR else None
                for i, b in enumerate(best)]
    return classify


def plan_of(prompt: str, gen=None) -> tuple[PartPlan | None, tuple[str, str] | None]:
    """(two-things plan or None, named side of a single-action prompt or None): the plan's reading
    (``plan.words.Words``), clauses the action patterns miss named by ``gen``'s known captions."""
    words = read_words(prompt)
    plan = words.parts
    if plan is None and gen is not None:
        plan = plan_parts(prompt, clause_classifier(gen))
    return plan, (None if plan is not None else words.side)


def generate_by_parts(gen, r, words=None, captured: bool = True) -> Motion | None:
    """The Motion of request ``r`` generated by part, or None when its prompt is neither two
    things at once nor names a side (the caller generates it whole); ``words``: an edited plan's
    reading (``plan.words.Words``), its parts and side taken as they are; ``captured`` False: the
    samples alone compete (an edit that cuts the codes follows: a stop)."""
    plan, side = plan_of(r.prompt, gen) if words is None else (words.parts, words.side)
    if plan is None and side is None:
        return None
    if plan is None:  # one action, a named side: judged on the planted motion, the one the user sees
        words = read_words(r.prompt)
        course = words.course                    # "paces back and forth, waving his right hand": its gait
        sampled = dataclasses.replace(r, prompt=words.straight_text) if course else r   # sampled straight
        choice = gen.choose(sampled, side, captured, body_of=r)   # captured takes, mirrored to the side, compete
        betas, source = choice.body, choice.body_source   # (planting, the foot roll above all, changes
        m = gen.chosen_motion(choice, betas, r.prompt)    # how far a foot travels)
        if choice.window is None and needs_mirror(m.joints, *side):
            m = assemble(gen.body, betas, _track(choice.codes, gen.vae, gen.body, betas, True), None, r.prompt,
                         gen.ik_refine_iters, tokens=np.asarray(choice.codes, np.int32), mirrored=True,
                         provenance=decoded_provenance(choice.kept))
        m.shape_source = source
        m.retrieved_clips = choice.clips
        return m if course is None else course_motion(m, gen.body, course, words.course_right, gen.ik_refine_iters,
                                                      r.whole_course)
    course = plan.legs_action if plan.legs_action in COURSE_ACTIONS else read_words(plan.legs_prompt).course
    gait = read_words(plan.legs_prompt).course_gait if course is not None else None   # walked straight, then bent
    legs_req = dataclasses.replace(r, prompt=gait[0], action=gait[1]) if gait else \
        dataclasses.replace(r, prompt=plan.legs_prompt, action=plan.legs_action)
    # each part its own choice among samples and captured takes (a course's gait: the samples, as one prompt's)
    legs_choice = gen.choose(legs_req, captured=captured and course is None, body_of=r, library_as_captured=False)
    betas, source = legs_choice.body, legs_choice.body_source
    legs = part_of(gen, legs_choice, betas)
    arms_req = dataclasses.replace(r, prompt=plan.arms_prompt, seconds=len(legs.track) / FPS, seed=r.seed + 1,
                                   action=plan.arms_action)
    arms_choice = gen.choose(arms_req, plan.arms_side, captured, body_of=r, library_as_captured=False)
    arms = part_of(gen, arms_choice, betas, plan.arms_side)
    held = (words if words is not None else read_words(r.prompt)).arms_held   # "with both arms raised"
    kept = held_from_peak(arms.track) if held else arms.track   # played to the raise's top, held there
    legs_track, arms_track = legs.track, fitted(kept, len(legs.track))
    played = legs.codes is None or arms.codes is None   # a take in it: played by rotations, no tokens
    tokens = {} if played or kept is not arms.track else dict(    # a held raise is an edit: no tokens kept
        tokens=np.asarray(legs.codes, np.int32), arms_tokens=np.asarray(arms.codes, np.int32),
        arms_mirrored=arms.mirrored)
    if course is not None:  # the codec does not carry turning: the words' course is walked (course_walk.py)
        right = read_words(plan.legs_prompt).course_right
        legs_track, tokens = on_course(legs_track, course, right, whole=r.whole_course), {}   # an edit: no tokens kept
    m = assemble(gen.body, betas, legs_track, arms_track, r.prompt, gen.ik_refine_iters,
                 known_contacts=legs.codes is None, **tokens)
    if played:   # another body plants it again by its rotations (retarget.replant), as a take
        m.contacts_measured = True
        m.provenance = f"legs: {legs.provenance}; arms: {arms.provenance}"
    for part, c in (("legs", legs_choice), ("arms", arms_choice)):   # what a part's words asked and it does not do
        for note in (c.note, c.window.note if c.window is not None else ""):
            if note:
                m.notes.append(f"{part}: {note}")
    if kept is not arms.track:
        m.notes.append(held_note(arms.track))
    if course is not None and not r.whole_course and (note := course_note(course, m.joints, m.fps)):
        m.notes.append(note)   # too short to go round its course
    m.shape_source = source
    m.part_prompts = (plan.legs_prompt, plan.arms_prompt)
    m.retrieved_clips = legs_choice.clips + arms_choice.clips
    return m


def is_by_parts(motion: Motion) -> bool:
    return motion.arms_tokens is not None or bool(motion.mirrored)


def redecode_parts(motion: Motion, vae, body, betas, ik_refine_iters: int = 10) -> Motion:
    """A by-part motion's tokens decoded for another body: the same composition and mirrors."""
    legs = _track(motion.tokens, vae, body, betas, motion.mirrored)
    arms = _track(motion.arms_tokens, vae, body, betas, motion.arms_mirrored) if motion.arms_tokens is not None else None
    if arms is not None and len(arms) != len(legs):
        raise ShapeMoveError(f"this motion's arms have {len(arms)} frames and its legs {len(legs)}; "
                             "it cannot be re-decoded (generate it again)")
    return assemble(body, betas, legs, arms, motion.prompt, ik_refine_iters, tokens=motion.tokens,
                    arms_tokens=motion.arms_tokens, mirrored=motion.mirrored, arms_mirrored=motion.arms_mirrored)
