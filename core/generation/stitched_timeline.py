"""A timeline of finished motions: each segment chosen as a single prompt is, then joined.

Where captured takes compete (``captured_takes.py``), a segment of a timeline is one more prompt:
its own pool of T5 samples and captured windows of the action its words ask, one choice by the TMA
on the finished motions, and every edit a single prompt gets (a stop, a count, a course, a turn,
a pace, on the spot) made by ``Generator.generate_batch`` on the timeline's one body. A code
timeline (``sequence.generate_sequence``) cannot hold a captured take: its segments are codes,
and the codes flatten a kick to standing.

The finished segments are joined on their joints (``stitch``): each next segment is turned about
the vertical so that it starts facing where the one before ends, and moved so that its root starts
where that one's ends; the difference left between the last pose and the next first pose (arms,
legs, the root's height) is carried into the next segment and faded out (smoothstep) over
``BLEND`` to ``MAX_BLEND`` frames, as long as no joint then moves more than ``FADE_SHARE`` of its
99th-percentile step a frame for the fade, so no frame jumps and each segment is its own motion
after the fade. The seams are
then paced (``seam_pace.paced_seams``) and the whole planted once on the body (``track.plant``).
The Motion is played by its rotations (no tokens, its contacts kept): another body plants it again
(``retarget.replant``); Regenerate samples one segment again and joins the rest as they are
(``regenerate_stitched``).

    motion = stitched_sequence(gen, [("a man walks forward", 3.0), ("he kicks", 2.0)], betas, Request(""))
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import ShapeMoveError
from ..scene.motion_file import Motion
from .seam_pace import paced_seams
from .track import Track, headings, plant, rotate_y, smoothstep

BLEND = 10       # frames (0.5 s): the shortest fade of the pose difference at a seam into the next segment
MAX_BLEND = 40   # frames (2 s): the longest
FADE_SHARE = 1 / 3   # the fade moves a joint at most this share of its 99th-percentile step a frame


def joined(prev: np.ndarray, nxt: np.ndarray, blend: int = BLEND) -> np.ndarray:
    """(T,22,3) joints of ``nxt`` placed after ``prev`` (module docstring): turned and moved so its
    root starts where ``prev``'s ends, facing as it ends (``track.headings``), and the remaining pose difference at
    the seam faded out over ``blend`` frames. The first frame continues ``prev`` by no more than
    ``nxt``'s own first step."""
    prev, nxt = np.asarray(prev, np.float64), np.asarray(nxt, np.float64)
    out = nxt.copy()
    out[..., [0, 2]] -= nxt[0, 0, [0, 2]]
    out = rotate_y(out, headings(prev)[-1] - headings(nxt)[0])
    out[..., [0, 2]] += prev[-1, 0, [0, 2]]
    first_step = out[1] - out[0] if len(out) > 1 else np.zeros_like(out[0])
    offset = prev[-1] + first_step - out[0]     # where the next first frame should be, continuing prev
    n = fade_frames(prev, out, offset, blend)
    fade = 1.0 - smoothstep(np.arange(len(out)) / n)   # 1 at the seam, 0 from n frames on
    return out + fade[:, None, None] * offset[None]


def fade_frames(prev: np.ndarray, nxt: np.ndarray, offset: np.ndarray, blend: int = BLEND) -> int:
    """Frames over which a seam's pose ``offset`` (22,3) fades: at least ``blend``, long enough that
    the fade (a smoothstep, fastest at 1.5x its mean) moves no joint more than ``FADE_SHARE`` of
    that joint's 99th-percentile step in the two segments a frame, at most ``MAX_BLEND`` and the
    next segment's length."""
    steps = np.linalg.norm(np.diff(np.concatenate([prev, nxt]), axis=0), axis=-1)   # (T-1, 22)
    p99 = np.maximum(np.percentile(steps, 99, axis=0), 0.005)
    need = int(np.ceil(1.5 * float((np.linalg.norm(offset, axis=-1) / p99).max()) / FADE_SHARE))
    return max(1, min(max(blend, need), MAX_BLEND, len(nxt)))


def stitch(joints: list[np.ndarray], contacts: list[np.ndarray], blend: int = BLEND) -> tuple[Track, np.ndarray]:
    """The segments' joints joined in order (``joined``) and their contacts; (Track, (S,2) bounds)."""
    if not joints or len(joints) != len(contacts):
        raise ShapeMoveError("a stitched timeline needs each segment's joints and contacts")
    out, con = [np.asarray(joints[0], np.float64)], [np.asarray(contacts[0], np.uint8)]
    for j, c in zip(joints[1:], contacts[1:]):
        out.append(joined(out[-1], j, blend))
        con.append(np.asarray(c, np.uint8))
    ends = np.cumsum([len(j) for j in out])
    bounds = np.stack([np.r_[0, ends[:-1]], ends], axis=1).astype(np.int64)
    return Track(np.concatenate(out), np.concatenate(con)), bounds


def _contacts(m: Motion) -> np.ndarray:
    if m.contacts is not None and len(m.contacts) == m.num_frames:
        return np.asarray(m.contacts, np.uint8)
    from ..motion.contacts import detect_contacts

    return np.asarray(detect_contacts(m.joints, m.fps), np.uint8)


def segment_request(base, text: str, seconds: float, body: np.ndarray, seed: int, words=None):
    """The ``Request`` of one segment: ``base``'s sampling, its own text and seconds on the
    timeline's ``body``; ``words``: an edited plan's reading of it (``plan.words.Words``), acted on."""
    from ..plan.plan import Plan, Segment

    plan = None if words is None else Plan(text, (Segment(text, 1.0, words),), float(seconds))
    return dataclasses.replace(base, prompt=text, seconds=float(seconds), betas=np.asarray(body, np.float32),
                               shape_text=None, seed=int(seed), plan=plan, words=None, whole_course=True)


def planted(gen, joints: list[np.ndarray], contacts: list[np.ndarray], prompts: list[str], betas,
            prompt: str | None = None) -> Motion:
    """Segments' joints and contacts on one body ``betas`` joined (``stitch``), paced and planted:
    the timeline Motion with its segments, played by its rotations."""
    from ..motion.features import motion_features

    track, bounds = stitch(joints, contacts)
    paced = paced_seams(track.joints, track.contacts, bounds)
    if paced is not None:
        track = Track(*paced)
    motion = plant(gen.body, np.asarray(betas, np.float32), track, gen.ik_refine_iters,
                   prompt=prompt or " -> ".join(prompts))
    motion.features = motion_features(motion)
    motion.contacts_measured = True     # played by its rotations: another body plants it again (replant)
    motion.segment_bounds, motion.segment_prompts = bounds, list(prompts)
    return motion


def segment_provenance(sources: list[str | None]) -> str:
    """A timeline's provenance from each segment's ("segment 1: generated; segment 2: captured: ...")."""
    return "; ".join(f"segment {i + 1}: {p or 'generated'}" for i, p in enumerate(sources))


def segment_sources(motion: Motion) -> list[str] | None:
    """Each segment's provenance of a stitched timeline (``segment_provenance`` read back), None when
    the motion's provenance is not one per segment."""
    parts = (motion.provenance or "").split("; ")
    if motion.segment_bounds is None or len(parts) != len(motion.segment_bounds):
        return None
    if not all(p.startswith(f"segment {i + 1}: ") for i, p in enumerate(parts)):
        return None
    return [p.split(": ", 1)[1] for p in parts]


def assembled(gen, motions: list[Motion], prompts: list[str], betas, prompt: str | None = None) -> Motion:
    """The finished segment ``motions`` (one body ``betas``) as one timeline (``planted``), with
    their provenances and notes."""
    motion = planted(gen, [m.joints for m in motions], [_contacts(m) for m in motions], prompts, betas, prompt)
    motion.provenance = segment_provenance([m.provenance for m in motions])
    motion.retrieved_clips = [c for m in motions for c in m.retrieved_clips]
    motion.notes = [f"segment {i + 1}: {n}" for i, m in enumerate(motions) for n in m.notes]
    return motion


def stitched_sequence(gen, segments: list[tuple[str, float]], body: np.ndarray, base, readings=None,
                      progress=None, cancel=None) -> Motion:
    """The timeline of ``segments`` [(prompt, seconds)] on the betas ``body``, each segment made as a
    single prompt (module docstring) with ``base``'s sampling (a ``Request``), seeds ``base.seed``,
    ``base.seed + 1``, ...; a segment standing up from the seat of the one before, that sit played
    backwards (``reversed_rise.py``); ``readings``: the plan's reading of each segment (None: its
    text's own)."""
    from ..plan.words import read_words

    said = [readings[i] if readings is not None and readings[i] is not None else read_words(text)
            for i, (text, _) in enumerate(segments)]
    motions = []
    for i, (text, sec) in enumerate(segments):
        if cancel is not None and cancel():
            raise ShapeMoveError("cancelled")
        asked = segment_request(base, text, sec, body, base.seed + i, None if readings is None else readings[i])
        motions.append(_segment_made(i, said, motions[-1] if i else None, sec,
                                     lambda seated: gen.generate_batch([dataclasses.replace(asked, seated=seated)])[0]))
        if progress is not None:
            progress((i + 1) / (len(segments) + 1), f"segment {i + 1}/{len(segments)}: {text}")
    return assembled(gen, motions, [t for t, _ in segments], body)


def _segment_made(i: int, said: list, before: Motion | None, seconds: float, make) -> Motion:
    """Segment ``i`` of a timeline whose segments' readings are ``said``: the segment ``before`` it
    played backwards when it stands up from the seat that one ends on (``reversed_rise.py``), else
    ``make(seated)``, ``seated`` when it lies down from that seat (``reversed_rise.lies_from_seat``),
    held at its lowest when the next segment stands up from it."""
    from ..constants import FPS
    from .reversed_rise import held_low, lies_from_seat, lowers, rises_from_seat, sit_reversed, stands_up

    if i and rises_from_seat(said[i - 1], said[i], before):   # standing up from the seat just sat on
        return sit_reversed(before, _contacts(before), max(2, int(round(seconds * FPS))), i)
    made = make(bool(i) and lies_from_seat(said[i - 1], said[i], before))
    if i + 1 < len(said) and lowers(said[i]) and stands_up(said[i + 1]):   # down, held, then up
        made = held_low(made, _contacts(made))
    return made


def is_stitched(motion: Motion) -> bool:
    """A timeline joined from finished segments (no tokens, played by its rotations)."""
    return motion.segment_bounds is not None and motion.num_tokens == 0 and motion.contacts_measured


def regenerate_stitched(gen, motion: Motion, index: int, seed: int, prompt: str | None = None,
                        seconds: float | None = None, request=None) -> Motion:
    """Segment ``index`` of a stitched timeline made again (new ``seed``, optionally a new ``prompt``
    or ``seconds``) as a single prompt on the timeline's body; the other segments keep their frames
    and are joined again around it. The standing up from a seat keeps to its seat
    (``reversed_rise.py``): a segment that rises from the one before is that segment played
    backwards again, and the rise after a segment made again is played backwards from the new one
    (a sit or a squat before a stand-up held at its lowest, as ``stitched_sequence`` makes them)."""
    import dataclasses

    from ..constants import FPS
    from ..plan.words import read_words
    from .request import Request
    from .reversed_rise import played_backwards, rises_from_seat, sit_reversed
    from .timeline_plan import plan_readings

    bounds = np.asarray(motion.segment_bounds)
    prompts = list(motion.segment_prompts)
    if not 0 <= index < len(bounds):
        raise ShapeMoveError(f"segment {index + 1} does not exist: this timeline has {len(bounds)}")
    text = prompt or prompts[index]
    sec = float(seconds) if seconds is not None else (bounds[index, 1] - bounds[index, 0]) / FPS
    joints = [np.asarray(motion.joints[s:e]) for s, e in bounds]
    whole = _contacts(motion)
    contacts = [whole[s:e] for s, e in bounds]
    sources = segment_sources(motion) or [None] * len(prompts)
    readings = plan_readings(motion) or [None] * len(prompts)   # an edited plan's actions, where it has them
    said = [read_words(t) if (i == index and t != prompts[index]) or readings[i] is None else readings[i]
            for i, t in enumerate(prompts[:index] + [text] + prompts[index + 1:])]
    segment = lambda i: dataclasses.replace(motion, joints=joints[i], contacts=contacts[i])  # noqa: E731
    base = request if request is not None else Request(text)
    new = _segment_made(index, said, segment(index - 1) if index else None, sec, lambda seated: gen.generate_batch(
        [dataclasses.replace(segment_request(base, text, sec, motion.betas, seed), seated=seated)])[0])
    joints[index], contacts[index] = np.asarray(new.joints), _contacts(new)
    prompts[index] = text
    sources[index] = new.provenance
    after = index + 1
    if after < len(prompts) and sources[after] == played_backwards(after):   # the rise from it, again
        if rises_from_seat(said[index], said[after], segment(index)):
            rise = sit_reversed(segment(index), contacts[index], len(joints[after]), after)
            joints[after], contacts[after] = np.asarray(rise.joints), _contacts(rise)
    out = planted(gen, joints, contacts, prompts, motion.betas, motion.prompt)
    out.provenance, out.shape_source = segment_provenance(sources), "given"
    out.plan = motion.plan if text == motion.segment_prompts[index] else None
    return out
