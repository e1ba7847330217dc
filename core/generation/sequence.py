"""A timeline of prompts: "walks forward" 4 s, then "sits down" 2 s, then "waves" 3 s, one body.

Each segment's motion codes are sampled with the T5 continuing from the previous segment's last
``PREFIX_CODES`` codes (``constrained_decoding.decode(prefix_codes=...)``): the decoder sees where
the body is and writes the next prompt's motion from there, so the transition is the model's, not
a cross-fade. Of ``candidates`` samples per segment the TMA keeps the one closest to that
segment's prompt (``rerank``). All codes are then decoded as one sequence by the SA-VAE for one
body (given betas, else the first segment's as a single prompt's: the shape text's measurements or
the [BETA] head's reading of it, else the prompt's person words or the average adult) and
planted once (``track.plant``). The Motion keeps ``segment_bounds`` (frames) and
``segment_prompts``; ``regenerate_segment`` samples one segment again (continuing from its
predecessor) and keeps every other segment's codes and frames: the SA-VAE's decoder reads far
around each code, so the timeline decoded again would move the neighbours too (by 1-6 cm with the
fine-tuned decoder); instead the new segment's frames are spliced between the old ones
(``splice``: the frames after it moved rigidly to where it ends, 6-frame fades at the seams).

A segment of two things at once ("walks on, waving"; ``parts.plan_of``) is made by body part, as a
single prompt is (``parts.py``): its legs prompt continues the timeline's codes, its arms prompt
the arms' codes, for as many codes. The arms' stream is the timeline's own codes wherever a segment
has no arms of its own, so decoding it gives the timeline's arms there, and ``compose_arms`` puts
the arms of that stream on the timeline's chest for the whole length: the decoder's own transition
between codes carries the arms into and out of the gesture. The Motion keeps both streams
(``tokens``, ``arms_tokens``), so re-decoding for another body composes them again. A named side
is kept: a segment of one action naming a side ("waves with the left hand") that the other side does
more of is replaced by its mirror image, mirrored by the codec itself (``_on_side``: decoded,
mirrored as features, encoded again), so the timeline's tokens carry the side.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..constants import FPS
from ..errors import ShapeMoveError
from ..scene.motion_file import Motion
from ..torch_threads import one_torch_thread
from .decode import decode_features
from .prompts import check_prompt
from .sampling_params import DEFAULT_CANDIDATES, check_candidates, check_sampling
from .seam_pace import paced_seams, seam_steps
from ..plan.words import read_words
from .stop_words import distance_cut, distance_keeps, from_start, standing_after, stop_cut
from .token_sampling import body_for, sample_codes
from .timeline_plan import plan_readings
from .track import Track, decoded_track, plant, rotate_y, smoothstep

PREFIX_CODES = 4          # codes (0.8 s at 4 frames a code) a segment continues from
SPLICE_BLEND = 6          # frames each side of a regenerated segment's seams that fade between old and new
MAX_SEGMENTS = 32
MAX_TOTAL_SECONDS = 120.0


@dataclass
class Segment:
    prompt: str
    seconds: float


def check_segments(segments) -> list[Segment]:
    out = []
    if not segments:
        raise ShapeMoveError("a timeline needs at least one --prompt with its --seconds")
    if len(segments) > MAX_SEGMENTS:
        raise ShapeMoveError(f"a timeline holds at most {MAX_SEGMENTS} prompts, got {len(segments)}")
    for i, seg in enumerate(segments, 1):
        prompt, seconds = (seg.prompt, seg.seconds) if isinstance(seg, Segment) else seg
        try:
            sec = float(seconds)
        except (TypeError, ValueError):
            raise ShapeMoveError(f"segment {i}: seconds must be a number, got {seconds!r}") from None
        if not 0.4 <= sec <= 60:
            raise ShapeMoveError(f"segment {i} ({str(prompt)[:30]!r}): seconds must be between 0.4 and 60, got {seconds}")
        out.append(Segment(check_prompt(prompt), sec))
    total = sum(s.seconds for s in out)
    if total > MAX_TOTAL_SECONDS:
        raise ShapeMoveError(f"a timeline is at most {MAX_TOTAL_SECONDS:g} s long, these segments add up to {total:g} s")
    return out


def _segment(gen, prompt, shape_text, n, prefix, arms_prefix, betas, seed, temperature, top_k, candidates, guidance,
             by_parts: bool, body=None, words=None):
    """(codes, the arms' codes or None, [BETA] prediction) of one segment: two things at once are
    made by part (module doc), standing still is the model's standing code (``stop_words.py``), a
    gait that stops or counts its steps ("takes three steps forward") stands after them (counted
    on the timeline's ``body``, the betas it plays on: a tall body's strides go further), any other
    prompt whole. ``words``: an edited plan's reading of the segment (``plan.words.Words``), acted on
    as it is; None: its text's."""
    from .parts import plan_of

    edited = words is not None
    words = read_words(prompt) if words is None else words
    if by_parts and words.stand_still and gen.rest_code is not None:   # no caption stands still: nothing
        pred = gen.predicted_betas(prompt, shape_text).numpy().astype(np.float32)  # to sample (stop_words.py)
        return [gen.rest_code] * n, None, pred
    stop = (words.gait_text, words.steps) if by_parts and words.stop else None   # the standing code is found
    stop = stop if stop is not None and gen.rest_code is not None else None      # only when one is asked
    metres = words.distance_m if stop is not None else None   # "walks 3 metres": that far, then stands
    prompt = prompt if stop is None else stop[0]
    plan, side = ((words.parts, words.side) if edited else plan_of(prompt, gen)) if by_parts else (None, None)
    legs = prompt if plan is None else plan.legs_prompt
    legs = read_words(legs).straight_text if by_parts else legs   # a course's gait, bent by timeline_words
    codes, pred = _segment_codes(gen, legs, shape_text, n, prefix, betas, seed, temperature, top_k, candidates,
                                 guidance, words if edited and plan is None else None)
    if plan is None:
        codes, arms = (_on_side(gen.vae, codes, prefix, side) if side is not None else codes), None
    else:
        arms, _ = _segment_codes(gen, plan.arms_prompt, shape_text, len(codes), arms_prefix, betas, seed + 1,
                                 temperature, top_k, candidates, guidance)
    keep = None if stop is None else _steps_kept(gen.vae, codes, prefix, stop[1], metres, body, gen.rest_code)
    if keep is not None:   # both parts stand after the counted steps (Generator.stopped for one prompt)
        codes = standing_after(codes, keep, gen.rest_code)
        arms = None if arms is None else standing_after(arms, keep, gen.rest_code)
    return codes, arms, pred


@torch.no_grad()
def _steps_kept(vae, codes: list[int], prefix: list[int], steps: int | None, metres: float | None = None,
                body=None, rest: int | None = None) -> int | None:
    """How many of a segment's gait ``codes`` its counted ``steps`` keep (``stop_words.stop_cut``), or
    its ``metres`` (``stop_words.distance_cut``; with the standing code ``rest``, of the cuts
    ``distance_keeps`` tries, the one whose motion, standing after it, ends nearest the distance), read from the foot
    contacts or the root the decoder gives them after the codes they continue, on the betas ``body``
    (None: the canonical body); None when the gait strikes fewer times or does not get that far."""
    from ..motion.contacts import to_feature_order
    from ..motion.features import joints_from_features

    down = vae.cfg.downsample
    betas = np.zeros(10, np.float32) if body is None else np.asarray(body, np.float32)

    def decoded(c):
        with one_torch_thread():
            return decode_features(list(prefix) + list(c), vae, betas).numpy()[len(prefix) * down:]

    feats = decoded(codes)
    if metres is not None:
        keep = distance_cut(joints_from_features(feats), metres, len(codes), down)
        if keep is None or rest is None:
            return keep
        gone = {k: float(from_start(joints_from_features(decoded(standing_after(codes, k, rest))))[-1])
                for k in distance_keeps(keep, len(codes))}
        return min(sorted(gone), key=lambda k: abs(gone[k] - metres))
    contacts = to_feature_order(feats[:, 259:263] > 0.5)   # the same swap puts them back in 7, 8, 10, 11
    return stop_cut(contacts, steps, len(codes), down)


@torch.no_grad()
def _on_side(vae, codes: list[int], prefix: list[int], side: tuple[str, str]) -> list[int]:
    """A segment's codes moving the named ``side`` (("left" | "right", "hand" | "foot")): as they
    are when that side moves most, else their mirror image, made by the codec itself: decoded after
    the codes it continues (on the canonical body), mirrored as features (``data.mirror``) and
    encoded again, so the timeline's tokens carry it (re-decoding for another body, regenerating a
    neighbour and splicing keep it). Base codes only: a timeline decodes through one decoder
    whichever of its segments were mirrored."""
    from ..data.mirror import mirror_features
    from ..motion.features import joints_from_features
    from .part_compose import needs_mirror

    down = vae.cfg.downsample
    with one_torch_thread():
        feats = decode_features(list(prefix) + list(codes), vae, np.zeros(10, np.float32))
        joints = joints_from_features(feats.double()).numpy()[len(prefix) * down:]
        if not needs_mirror(joints, *side):
            return list(codes)
        mirrored = torch.as_tensor(mirror_features(feats.numpy()))
        tokens = vae.encode(vae.normalize(mirrored)[None])[1][0]  # base codes, as the T5 writes them
    return [int(t) for t in tokens[len(prefix):]]


def _arms_stream(codes_per_segment, arms_per_segment) -> list[int]:
    """The arms' codes: a segment's own, else the timeline's."""
    arms_per_segment = arms_per_segment or [None] * len(codes_per_segment)
    return [c for seg, a in zip(codes_per_segment, arms_per_segment) for c in (seg if a is None else a)]


def _segment_codes(gen, prompt, shape_text, n, prefix, betas, seed, temperature, top_k, candidates, guidance,
                   words=None):
    cands, pred = sample_codes(gen, prompt, shape_text, candidates, n, n, seed, temperature, top_k, guidance,
                               prefix=prefix)
    best = 0
    if len(cands) > 1 and gen.picker is not None:
        b = pred if betas is None else betas
        skip = len(prefix) * gen.vae.cfg.downsample   # judge the segment's own frames
        feats = [f[skip:] for f in _batch_features(gen.vae, [list(prefix) + c for c in cands], b)]
        best = gen.picker.pick(prompt, feats, words=words)
    return cands[best], pred


@torch.no_grad()
def _batch_features(vae, codes: list[list[int]], betas) -> list[np.ndarray]:
    """``decode.decode_features`` of equally long code lists in one SA-VAE pass."""
    with one_torch_thread():
        idx = torch.as_tensor(codes, dtype=torch.long)
        b = torch.as_tensor(np.asarray(betas, np.float32))[None].expand(len(codes), -1)
        out = vae.denormalize(vae.decode_tokens_long(idx, b))
    return [f.numpy() for f in out]


def _timeline_track(gen, codes_per_segment, betas, arms_per_segment=None) -> tuple[Track, np.ndarray | None, dict]:
    """The decoded (and, with arms of their own, composed) track of a timeline's codes; its
    decoded features (None when composed) and the Motion fields that go with it."""
    codes = [c for seg in codes_per_segment for c in seg]
    track, feats = decoded_track(codes, gen.vae, gen.body, betas)
    extra = {"tokens": np.asarray(codes, np.int32)}
    if arms_per_segment is not None and any(a is not None for a in arms_per_segment):
        from .part_compose import compose_arms

        arms = _arms_stream(codes_per_segment, arms_per_segment)
        arms_track, _ = decoded_track(arms, gen.vae, gen.body, betas)
        track = Track(compose_arms(track.joints, arms_track.joints), track.contacts)
        extra["arms_tokens"], feats = np.asarray(arms, np.int32), None
    return track, feats, extra


def _planted(gen, track: Track, feats, extra: dict, codes_per_segment, prompts, betas, words: bool = True,
             readings=None) -> Motion:
    """The timeline's track planted, with its segments; ``words``: each segment's pace and travel
    words obeyed first (``timeline_words.py``; ``readings``: an edited plan's, per segment, else
    their texts'); the seams paced (``seam_pace.py``)."""
    down = len(track) // sum(len(c) for c in codes_per_segment)
    ends = np.cumsum([len(c) for c in codes_per_segment]) * down
    bounds = np.stack([np.r_[0, ends[:-1]], ends], axis=1).astype(np.int64)
    if words:
        from .timeline_words import worded_joints

        worded = worded_joints(track.joints, bounds, prompts, readings)
        if worded is not None:
            track, feats = Track(worded, track.contacts), None
    paced = paced_seams(track.joints, track.contacts, bounds)   # no seam faster than the segments: the
    if paced is not None:                                        # decoder's features kept (a re-timing
        track = Track(*paced)                                    # of the frames around the seams)
    motion = plant(gen.body, betas, track, gen.ik_refine_iters, prompt=" -> ".join(prompts), features=feats, **extra)
    if feats is None:  # composed, spliced or worded: the planted motion's features, as parts.assemble computes them
        from ..motion.features import motion_features

        motion.features = motion_features(motion)
    motion.segment_bounds = bounds
    motion.segment_prompts = list(prompts)
    return motion


def _assemble(gen, codes_per_segment, prompts, betas, arms_per_segment=None, words: bool = True,
              readings=None) -> Motion:
    track, feats, extra = _timeline_track(gen, codes_per_segment, betas, arms_per_segment)
    return _planted(gen, track, feats, extra, codes_per_segment, prompts, betas, words, readings)


def redecode_timeline(gen, motion: Motion, betas) -> Motion:
    """A timeline's codes (and its arms' codes) decoded and planted again for the body ``betas``,
    as generation assembles it (its segments' words obeyed), segments kept."""
    from .decode import check_betas

    arms = segment_codes(motion, arms=True) if motion.arms_tokens is not None else None
    out = _assemble(gen, segment_codes(motion), list(motion.segment_prompts), check_betas(betas), arms,
                    readings=plan_readings(motion))
    out.shape_source, out.plan = "given", motion.plan
    return out


def splice(old: Track, new: Track, start: int, old_end: int, new_end: int, blend: int = SPLICE_BLEND) -> Track:
    """``new`` (a timeline decoded with one segment changed: frames ``start``..``new_end``) with
    every other frame taken from ``old`` (the timeline before: that segment was ``start``..``old_end``).
    The old frames after the segment are moved rigidly (ground-plane turn and shift) so that where
    the old segment ended sits where the new one ends. Each seam fades from one track to the other
    over ``blend`` frames on either side (smoothstep; the old track's own frames on its side of the
    seam), contacts switching at the middle of the fade."""
    from .track import headings, root_centre

    oj, nj = old.joints, new.joints
    T = len(nj)
    if len(oj) - old_end != T - new_end or not 0 <= start <= min(old_end, new_end):
        raise ShapeMoveError(f"splice: a segment {start}..{old_end} of {len(oj)} frames cannot become "
                             f"{start}..{new_end} of {T}")
    other, ocon = nj.copy(), new.contacts.copy()
    head = min(start + blend, old_end, new_end)           # the old track runs on into its old segment
    other[:head], ocon[:head] = oj[:head], old.contacts[:head]
    nb = min(blend, old_end - start, new_end - start)    # and the old segment's last frames lead into its tail
    if new_end - nb < T:
        i, j = min(old_end, len(oj) - 1), min(new_end, T - 1)
        moved = oj[old_end - nb:].copy()
        moved[..., [0, 2]] -= root_centre(oj)[i]
        moved = rotate_y(moved, headings(nj)[j] - headings(oj)[i])
        moved[..., [0, 2]] += root_centre(nj)[j]
        other[new_end - nb:], ocon[new_end - nb:] = moved, old.contacts[old_end - nb:]
    k = np.arange(T, dtype=np.float64)

    def rise(centre):
        return smoothstep((k - (centre - blend)) / (2 * blend))

    w = np.minimum(rise(start) if start > 0 else 1.0, 1.0 - rise(new_end) if new_end < T else 1.0)
    joints = w[:, None, None] * nj + (1 - w[:, None, None]) * other
    contacts = np.where((w >= 0.5)[:, None], new.contacts, ocon)
    return Track(joints, contacts)


def generate_sequence(gen, segments, shape_text: str | None = None, betas=None, seed: int = 0,
                      temperature: float = 1.0, top_k: int | None = 50, candidates: int = DEFAULT_CANDIDATES,
                      guidance: float | None = None, progress=None, cancel=None, by_parts: bool = True,
                      readings=None) -> Motion:
    """``segments``: [(prompt, seconds)] or ``Segment``s -> one Motion with segment_bounds;
    ``by_parts``: segments of two things at once made by body part (module doc); ``readings``: an
    edited plan's reading of each segment (``plan.words.Words``), acted on instead of their texts'."""
    segs = check_segments(segments)
    shape_text = check_prompt(shape_text, "shape text", allow_empty=True) or None
    seed, temperature, top_k = check_sampling(seed, temperature, top_k)
    candidates = check_candidates(candidates)
    warnings = []
    for s in segs:  # every text checked before any generation
        check = gen.check_text(s.prompt)
        if check is not None and check.warning:
            warnings.append(check.warning)
    if shape_text:
        gen.check_text(shape_text, "shape text")
    down = gen.vae.cfg.downsample
    # one body for the whole timeline: the first segment's, as a single prompt's (``body_for``),
    # known before any stop is cut
    body, source = body_for(gen, segs[0].prompt, shape_text, betas,
                            gen.predicted_betas(segs[0].prompt, shape_text).numpy())
    if by_parts and gen.captured_on and gen.pool is not None and len(gen.pool):   # captured takes compete:
        from .request import Request                                              # each segment a prompt of
        from .stitched_timeline import stitched_sequence                          # its own, joined

        base = Request(segs[0].prompt, None, None, None, seed, temperature, top_k, candidates=candidates,
                       guidance=guidance)
        motion = stitched_sequence(gen, [(s.prompt, s.seconds) for s in segs], body, base, readings, progress, cancel)
        motion.shape_source, motion.warnings = source, warnings
        if progress is not None:
            progress(1.0, "timeline planted")
        return motion
    chosen, arms = [], []
    for i, s in enumerate(segs):
        if cancel is not None and cancel():
            raise ShapeMoveError("cancelled")
        n = max(1, int(round(s.seconds * FPS / down)))
        prefix = [c for seg in chosen for c in seg][-PREFIX_CODES:]
        codes, own_arms, _ = _segment(gen, s.prompt, shape_text, n, prefix, _arms_stream(chosen, arms)[-PREFIX_CODES:],
                                      betas, seed + i, temperature, top_k, candidates, guidance, by_parts, body,
                                      None if readings is None else readings[i])
        chosen.append(codes)
        arms.append(own_arms)
        if progress is not None:
            progress((i + 1) / (len(segs) + 1), f"segment {i + 1}/{len(segs)}: {s.prompt}")
    motion = _assemble(gen, chosen, [s.prompt for s in segs], body, arms, words=by_parts, readings=readings)
    motion.shape_source = source
    motion.warnings = warnings
    if progress is not None:
        progress(1.0, "timeline planted")
    return motion


def segment_codes(motion: Motion, arms: bool = False) -> list:
    """The codes of each segment of a timeline motion; ``arms``: the arms' codes of each segment
    instead (None where a segment has none of its own)."""
    if motion.segment_bounds is None or motion.tokens is None or len(motion.tokens) == 0:
        raise ShapeMoveError("this motion is not a timeline of prompts (no segments or no tokens)")
    down = motion.num_frames // len(motion.tokens)
    if down < 1 or down * len(motion.tokens) != motion.num_frames:
        raise ShapeMoveError("this timeline's frames do not match its tokens (was it time-warped?); generate it again")
    toks = [int(t) for t in motion.tokens]
    per = [toks[s // down:e // down] for s, e in np.asarray(motion.segment_bounds)]
    if not arms:
        return per
    if motion.arms_tokens is None:
        return [None] * len(per)
    own = [int(t) for t in motion.arms_tokens]
    return [None if own[s // down:e // down] == seg else own[s // down:e // down]
            for seg, (s, e) in zip(per, np.asarray(motion.segment_bounds))]


def regenerate_segment(gen, motion: Motion, index: int, seed: int, prompt: str | None = None,
                       seconds: float | None = None, temperature: float = 1.0, top_k: int | None = 50,
                       candidates: int = DEFAULT_CANDIDATES, guidance: float | None = None,
                       by_parts: bool = True) -> Motion:
    """Segment ``index`` sampled again (new ``seed``, optionally a new ``prompt``/``seconds``),
    continuing from the previous segment; every other segment keeps its codes (and its arms'), the
    body its betas; a timeline held in place is held in place again. A timeline joined from finished
    segments (``stitched_timeline.py``) has that segment made again as a prompt of its own."""
    from .stitched_timeline import is_stitched, regenerate_stitched

    if is_stitched(motion):
        from .request import Request

        base = Request(prompt or "", None, None, None, seed, temperature, top_k, candidates=candidates,
                       guidance=guidance, by_parts=by_parts)
        out = regenerate_stitched(gen, motion, index, seed, prompt, seconds, base)
        if motion.held_in_place:
            from .in_place import in_place

            out = in_place(out)
        return out
    old_per, old_arms = segment_codes(motion), segment_codes(motion, arms=True)
    per, arms = list(old_per), list(old_arms)
    prompts = list(motion.segment_prompts)
    if not 0 <= index < len(per):
        raise ShapeMoveError(f"segment {index + 1} does not exist: this timeline has {len(per)}")
    seg = check_segments([(prompt or prompts[index], seconds if seconds is not None else
                           len(per[index]) * gen.vae.cfg.downsample / FPS)])[0]
    seed, temperature, top_k = check_sampling(seed, temperature, top_k)
    n = max(1, int(round(seg.seconds * FPS / gen.vae.cfg.downsample)))
    prefix = [c for s in per[:index] for c in s][-PREFIX_CODES:]
    arms_prefix = _arms_stream(per[:index], arms[:index])[-PREFIX_CODES:]
    readings = plan_readings(motion)
    if readings is not None and seg.prompt != prompts[index]:   # a new prompt: its own words
        readings[index] = read_words(seg.prompt)
    per[index], arms[index], _ = _segment(gen, seg.prompt, None, n, prefix, arms_prefix, motion.betas, seed, temperature,
                                          top_k, check_candidates(candidates), guidance, by_parts, motion.betas,
                                          None if readings is None else readings[index])
    same_plan = seg.prompt == prompts[index]
    prompts[index] = seg.prompt
    # the other segments keep their frames: the decoder reads far around a code, so decoding the
    # new codes as one sequence would also move the neighbours (module doc, ``splice``)
    down = gen.vae.cfg.downsample
    before, _, _ = _timeline_track(gen, old_per, motion.betas, old_arms)
    after, _, extra = _timeline_track(gen, per, motion.betas, arms)
    start = sum(len(c) for c in per[:index]) * down
    old_end = start + len(old_per[index]) * down
    track = splice(before, after, start, old_end, start + len(per[index]) * down)
    out = _planted(gen, track, None, extra, per, prompts, motion.betas, words=by_parts, readings=readings)
    out.shape_source, out.plan = "given", motion.plan if same_plan else None
    if motion.held_in_place:   # a timeline held in place stays so
        from .in_place import in_place

        out = in_place(out)
    return out


def scaled_bounds(bounds, num_frames: int) -> np.ndarray:
    """Segment bounds of a timeline re-timed to ``num_frames`` frames (consecutive, non-empty)."""
    b = np.asarray(bounds, np.float64)
    ends = np.round(b[:, 1] * num_frames / b[-1, 1]).astype(np.int64)
    ends = np.maximum(ends, np.arange(1, len(ends) + 1))
    ends[-1] = num_frames
    return np.stack([np.r_[0, ends[:-1]], ends], axis=1)


def boundary_report(motion: Motion) -> dict:
    """Per boundary, the worst joint's step across it (within ``seam_pace.SEAM`` frames: the
    decoder's transition takes about a code) over that joint's 99th percentile step inside the
    segments (``jump_ratio``: the worst over all boundaries)."""
    if motion.segment_bounds is None:
        raise ShapeMoveError("this motion has no segments")
    starts = [int(s) for s in np.asarray(motion.segment_bounds)[1:, 0]]
    ratios = seam_steps(motion.joints, starts)
    return {"boundaries": starts, "ratios": ratios, "jump_ratio": max(ratios, default=0.0)}


def segment_scores(gen, motion: Motion) -> np.ndarray:
    """(S prompts, S segments) TMA cosine similarity of each segment's features to each of the
    timeline's prompts: a segment is "the action asked" when its own prompt scores highest
    (the model's TMA; biased upward when the TMA also picked the candidates, see ``rerank``)."""
    if gen.picker is None:
        raise ShapeMoveError(f"{gen.model_dir} has no tma/ model to judge the segments with")
    if (motion.features is None or not 0 <= motion.num_frames - len(motion.features) <= 1
            or motion.segment_bounds is None):   # the planted motion's own features are a frame shorter
        raise ShapeMoveError("judging segments needs a timeline with its features")
    feats = [np.asarray(motion.features[s:e]) for s, e in motion.segment_bounds]
    return np.stack([gen.picker.scores(p, feats) for p in motion.segment_prompts])
