"""Loops: a motion whose last frame flows into its first, pose and velocity, for cycles.

The model makes the loop where it can: ``generate_loop`` samples several token sequences for the
prompt (``token_sampling``), and in each decoded joint track ``best_cut`` looks for two frames a < b,
at least ``MIN_PERIOD`` s apart, where the body's pose relative to its root and heading, and the
joints' velocities in that frame, are most alike. The candidate and cut with the smallest seam
win; frames a..b-1 are the cycle (the best ``PLANTED_TRIES`` cuts are planted in order until
one's planted seam, ``seam_report``, is within ``GOOD_SEAM``, else the best of them is kept:
planting moves joints the decoder barely moves, legs under a wave, by more than their own steps).
``make_cycle`` then removes what is left:
- the heading turns by the small angle between a and b, spread over the cycle, so every cycle
  travels the same way (a straight walk stays straight; Blender's Cycles modifier repeats it with
  an offset, never a rotation);
- the remaining joint offset between frame b and frame a (moved by the cycle's advance) is blended
  in over the last ``BLEND`` frames only (smoothstep), so frame b is frame a moved by the advance.
``plant_loop`` plants the feet on three copies of the cycle in a row and keeps the middle one, so
the contact runs that cross the seam are planted as one run. ``Motion.loop_advance`` is the
root's travel per cycle: frame T continues as frame 0 moved by it.

With a library (``Generator.add_library``), a clip of it that the prompt keeps and the codes cannot
carry (``library_takes.py``) is looped as captured (``loop_motion`` of ``Generator.library_take``).
"""
from __future__ import annotations


import numpy as np
import torch

from ..constants import FPS
from ..errors import ShapeMoveError
from ..motion.skeleton_ops import facing_directions, heading_angles
from ..scene.motion_file import Motion, make_motion
from ..plan.words import read_words
from .on_the_spot import LOOP_ALLOWED, spot_track
from .prompts import check_prompt
from .sampling_params import DEFAULT_CANDIDATES, check_candidates, check_sampling
from .token_sampling import body_for, sample_codes
from .loop_cut import EDGE, MIN_PERIOD, Cut, _local, best_cut  # noqa: F401  (where a motion loops)
from .track import Track, decoded_track, headings, plant, rotate_y, smoothstep, track_of, yaw_matrix

BLEND = 6              # frames over which the seam's last offset is blended in
PLANTED_TRIES = 3      # the best cuts planted until one's seam is good (``seam_report``)
GOOD_SEAM = 1.5        # worst joint's wrap jump over its mean step that ends the search (the target)
LOOP_MIN_SECONDS = 4.0  # candidates are at least this long, so a cycle has room
PART_SECONDS = 6.0     # a by-part motion's length when the loop's length is not asked for
PART_TRIES = 3         # by-part motions (seeds seed, seed + 2, ...) whose cycles compete


def make_cycle(track: Track, cut: Cut, blend: int = BLEND) -> tuple[Track, np.ndarray]:
    """Frames cut.start..cut.end-1 of ``track`` as a cycle -> (cycle track, advance (3,), y = 0)."""
    a, b = cut.start, cut.end
    P = b - a
    J = track.joints[a:b + 1].copy()
    h = headings(track.joints)
    turn = np.angle(np.exp(1j * (h[b] - h[a])))            # wrapped to (-pi, pi]
    pivot = np.array([J[0, 0, 0], 0.0, J[0, 0, 2]])
    J = rotate_y(J - pivot, -turn * np.arange(P + 1) / P) + pivot
    advance = np.array([J[P, 0, 0] - J[0, 0, 0], 0.0, J[P, 0, 2] - J[0, 0, 2]])
    residual = J[0] + advance - J[P]                        # (22,3)
    n = max(1, min(int(blend), P - 1))
    w = smoothstep((np.arange(P + 1) - (P - n)) / n)
    J += w[:, None, None] * residual[None]
    return Track(J[:P], track.contacts[a:b]), advance


def plant_loop(body, betas, cycle: Track, advance, ik_refine_iters: int = 10, prompt: str | None = None) -> Motion:
    """Plant the feet of a cycle: three copies in a row (moved by -advance, 0, +advance) planted
    together, the middle one kept, so runs that cross the seam stay one planted run."""
    P = len(cycle)
    adv = np.asarray(advance, np.float64)
    tiles = Track(np.concatenate([cycle.joints - adv, cycle.joints, cycle.joints + adv]),
                  np.concatenate([cycle.contacts] * 3))
    m3 = plant(body, betas, tiles, ik_refine_iters, prompt=prompt)
    planted_adv = m3.joints[2 * P, 0] - m3.joints[P, 0]
    loop_adv = np.array([planted_adv[0], 0.0, planted_adv[2]], np.float32)
    poses, transl = close_cycle(m3.poses[P:2 * P + 1], m3.transl[P:2 * P + 1], loop_adv)
    m = make_motion(body, poses, transl, betas, fps=m3.fps, prompt=prompt,
                    network_joints=cycle.joints.astype(np.float32), contacts=m3.contacts[P:2 * P],
                    loop_advance=loop_adv)
    m.ik_error_cm = m3.ik_error_cm
    return m


def close_cycle(poses, transl, advance) -> tuple[np.ndarray, np.ndarray]:
    """(P+1,24,3) axis-angle poses and (P+1,3) transl of a planted cycle plus its natural next frame
    -> the P frames of the cycle with that next frame made exactly frame 0 moved by ``advance``: the
    (sub-millimetre, IK-refinement) difference is spread linearly over the whole cycle."""
    from ..geometry.rotations import axis_angle_to_matrix, matrix_to_axis_angle

    R = axis_angle_to_matrix(np.asarray(poses, np.float64))
    P = len(R) - 1
    fix = matrix_to_axis_angle(np.swapaxes(R[P], -1, -2) @ R[0])            # R[P] @ exp(fix) = R[0]
    w = np.arange(P) / P
    R = R[:P] @ axis_angle_to_matrix(w[:, None, None] * fix[None])
    t = np.asarray(transl, np.float64)
    t = t[:P] + w[:, None] * (t[0] + np.asarray(advance, np.float64) - t[P])[None]
    return matrix_to_axis_angle(R).astype(np.float32), t.astype(np.float32)


def replant_loop(motion: Motion, body, betas, ik_refine_iters: int = 10) -> Motion:
    """A loop moved onto the body ``betas`` by its own rotations, as a take is (``retarget.replant``:
    the stride scaled by leg length, its contacts planted again), where a body-shape slider alone
    would keep the old stride on the new legs. Three copies in a row are moved together and the
    middle one kept (as ``plant_loop`` plants), so the contact runs crossing the seam stay one run
    and the cycle still closes; its advance is the new body's."""
    from .retarget import replant

    if not motion.planted_loop:
        raise ShapeMoveError("only a loop with its planted contacts and its travel (loop_advance, contacts, not held "
                             "in place) is moved onto a new body")
    P = motion.num_frames
    adv = np.asarray(motion.loop_advance, np.float64)
    shift = np.repeat(np.arange(-1, 2), P)[:, None] * adv[None]                  # (3P,3) each copy's offset
    three = Motion(joints=np.tile(motion.joints, (3, 1, 1)) + shift[:, None].astype(np.float32),
                   betas=motion.betas, poses=np.tile(motion.poses, (3, 1, 1)),
                   transl=(np.tile(motion.transl, (3, 1)) + shift).astype(np.float32), fps=motion.fps,
                   body_model=motion.body_model, prompt=motion.prompt, contacts=np.tile(motion.contacts, (3, 1)),
                   contacts_measured=True)
    m3 = replant(three, body, betas, ik_refine_iters)
    moved = m3.transl[2 * P] - m3.transl[P]
    loop_adv = np.array([moved[0], 0.0, moved[2]], np.float32)
    poses, transl = close_cycle(m3.poses[P:2 * P + 1], m3.transl[P:2 * P + 1], loop_adv)
    # a planted take starts facing +Z: turned back to the loop's own first facing, where it went before
    (was, now), rest = heading_angles(facing_directions(np.stack([motion.joints[0], m3.joints[P]]))), \
        body.rest_joints(torch.as_tensor(np.asarray(m3.betas, np.float32))[None])[0, 0].numpy()
    poses, transl = turned_about_y(poses, transl, rest, was - now)
    loop_adv = rotate_y(loop_adv, was - now).astype(np.float32)
    transl[:, [0, 2]] += motion.joints[0, 0, [0, 2]] - (transl[0, [0, 2]] + rest[[0, 2]])   # and where it started
    m = make_motion(body, poses, transl, m3.betas, fps=motion.fps, prompt=motion.prompt,
                    contacts=m3.contacts[P:2 * P], contacts_measured=motion.contacts_measured, loop_advance=loop_adv)
    m.notes, m.ik_error_cm = list(motion.notes), m3.ik_error_cm
    return m


def turned_about_y(poses, transl, rest_root, angle: float) -> tuple[np.ndarray, np.ndarray]:
    """(T,24,3) axis-angle poses and (T,3) transl of a body turned by ``angle`` about the vertical
    through the origin (``rest_root``: the body's rest root joint, which transl offsets)."""
    from ..geometry.rotations import axis_angle_to_matrix, matrix_to_axis_angle

    R = axis_angle_to_matrix(np.asarray(poses, np.float64))
    R[:, 0] = yaw_matrix(angle) @ R[:, 0]
    root = rotate_y(np.asarray(transl, np.float64) + rest_root, angle) - rest_root
    return matrix_to_axis_angle(R).astype(np.float32), root.astype(np.float32)


def loop_motion(motion: Motion, body, seconds: float | None = None, ik_refine_iters: int = 10) -> Motion:
    """An existing motion made into a loop (its best cut, see the module doc)."""
    track = track_of(motion)
    period = None if seconds is None else (0.85 * seconds, 1.15 * seconds)
    cut = best_cut(track.joints, motion.fps, period)
    cycle, adv = make_cycle(track, cut)
    m = plant_loop(body, motion.betas, cycle, adv, ik_refine_iters, prompt=motion.prompt)
    m.seam_cost = cut.cost
    return m


def _library_loop(gen, req, lo: int, hi: int):
    """A loop of the user's library clip that ``req`` keeps among the samples when the codes cannot
    carry it (``Generator.library_take``: played as captured, feet planted), cut where it loops
    best; None without a library, when none of its clips competes for the prompt (nothing is
    sampled then: the loop's own samples follow), or when a sample or a window the codes carry wins
    (it is looped from its codes as any sample)."""
    from dataclasses import replace

    seconds = hi * gen.vae.cfg.downsample / FPS if lo == hi else None
    asked = replace(req, seconds=seconds)
    if not gen.offers_library(asked):
        return None
    chosen = gen.tokens_for([asked], library_as_captured=True)
    betas, source = body_for(gen, req.prompt, req.shape_text, req.betas, chosen.betas[0].numpy())
    take = gen.library_take(chosen.kept[0], chosen.codes[0], betas, req.prompt)
    if take is None:
        return None
    m = loop_motion(take, gen.body, req.seconds, gen.ik_refine_iters)
    m.shape_source, m.notes, m.retrieved_clips = source, list(take.notes), [chosen.kept[0]]
    return m


def generate_loop(gen, req, progress=None, cancel=None) -> Motion:
    """A looping motion for ``req`` (a ``generate.Request``; ``seconds``: the cycle's length,
    +-15 %): ``req.candidates`` token samples, the best seam of all (``best_cut``) kept."""
    req.prompt = check_prompt(req.prompt)
    req.shape_text = check_prompt(req.shape_text, "shape text", allow_empty=True) or None
    req.seed, req.temperature, req.top_k = check_sampling(req.seed, req.temperature, req.top_k)
    n = check_candidates(req.candidates or DEFAULT_CANDIDATES)
    check = gen.check_text(req.prompt)
    down = gen.vae.cfg.downsample
    no_part_loop = False
    if req.seconds is not None:
        if not 0.4 <= req.seconds <= 30:
            raise ShapeMoveError(f"a loop's --seconds must be between 0.4 and 30, got {req.seconds}")
        codes = max(2, int(round(max(req.seconds * 1.6, req.seconds + 2.0) * FPS / down)))
        lo = hi = codes
        period = (0.85 * req.seconds, 1.15 * req.seconds)
    else:
        lo, hi = int(round(LOOP_MIN_SECONDS * FPS / down)), max(gen.max_codes, int(round(LOOP_MIN_SECONDS * FPS / down)))
        period = None
    if req.by_parts:  # two things at once or a named side: the by-part motion, looped
        if progress is not None:
            progress(0.1, "generating by body part")
        m = _loop_by_parts(gen, req, lo * down / FPS if req.seconds is not None else PART_SECONDS, period, cancel)
        if m is not False:
            if m is not None:
                m.warnings = [check.warning] if check is not None and check.warning else []
                m.prompt_check = check
                return m
            no_part_loop = True
    if progress is not None:
        progress(0.1, "sampling loop candidates")
    m = _library_loop(gen, req, lo, hi)
    if m is not None:   # the user's own clip, as captured
        m.warnings = [check.warning] if check is not None and check.warning else []
        m.prompt_check = check
        return m
    cands, pred = sample_codes(gen, req.prompt, req.shape_text, n, lo, hi, req.seed, req.temperature, req.top_k,
                               req.guidance)
    betas, source = body_for(gen, req.prompt, req.shape_text, req.betas, pred)
    found = []
    for codes in cands:
        if cancel is not None and cancel():
            raise ShapeMoveError("cancelled")
        track, _ = decoded_track(codes, gen.vae, gen.body, betas)
        track = spot_track(track, read_words(req.prompt).in_place, LOOP_ALLOWED) or track   # "jogs in place": on the spot (on_the_spot.py)
        try:
            found.append((track, best_cut(track.joints, FPS, period)))
        except ShapeMoveError:
            continue
    if not found:
        raise ShapeMoveError(f"none of the {len(cands)} samples of {req.prompt!r} holds a loop; try --seconds or another seed")
    found.sort(key=lambda f: f[1].cost)
    m, best = None, None
    for i, (track, cut) in enumerate(found[:PLANTED_TRIES]):
        # the seam is judged again once planted: the IK and grounding move joints that the
        # decoder barely moves (legs under a wave) by more than their own steps
        if cancel is not None and cancel():
            raise ShapeMoveError("cancelled")
        if progress is not None:
            progress(0.5 + 0.4 * i / PLANTED_TRIES, "planting the cycle")
        cycle, adv = make_cycle(track, cut)
        planted = plant_loop(gen.body, betas, cycle, adv, gen.ik_refine_iters, prompt=req.prompt)
        ratio = seam_report(planted)["jump_ratio"]
        if m is None or ratio < best[0]:
            m, best = planted, (ratio, cut)
        if ratio <= GOOD_SEAM:
            break
    m.shape_source = source
    m.warnings = [check.warning] if check is not None and check.warning else []
    if req.by_parts and no_part_loop:
        m.warnings.append("no loop was found in the motion made by body part: the prompt was generated whole")
    m.prompt_check = check
    m.seam_cost = best[1].cost
    return m


def _loop_by_parts(gen, req, seconds: float, period, cancel=None):
    """A loop of the by-part motion (``parts.generate_by_parts``) of ``req``: ``PART_TRIES`` of them
    (seeds 2 apart: a by-part motion uses its seed + 1 for the arms), each cut where it loops best
    and planted. Of those whose planted seam is good (else the best seam alone), the text-motion
    model keeps the cycle closest to the prompt: the best seam of a walk and a wave can fall where
    the hand is down. False when the prompt is one action with no named side (the caller loops it
    whole), None when no motion holds a loop."""
    import dataclasses

    from ..motion.features import motion_features
    from .parts import generate_by_parts

    tried = []
    for k in range(PART_TRIES):
        if cancel is not None and cancel():
            raise ShapeMoveError("cancelled")
        made = generate_by_parts(gen, dataclasses.replace(req, seconds=seconds, seed=req.seed + 2 * k))
        if made is None:
            return False
        track = track_of(made)
        try:
            cut = best_cut(track.joints, made.fps, period)
        except ShapeMoveError:
            continue
        cycle, adv = make_cycle(track, cut)
        m = plant_loop(gen.body, made.betas, cycle, adv, gen.ik_refine_iters, prompt=req.prompt)
        m.shape_source, m.part_prompts, m.retrieved_clips = made.shape_source, made.part_prompts, made.retrieved_clips
        m.seam_cost = cut.cost
        tried.append((seam_report(m)["jump_ratio"], m))
    if not tried:
        return None
    good = [m for r, m in tried if r <= GOOD_SEAM] or [min(tried, key=lambda t: t[0])[1]]
    if len(good) > 1 and gen.picker is not None:
        return good[gen.picker.pick(req.prompt, [motion_features(m) for m in good])]
    return good[0]


def seam_report(motion: Motion) -> dict:
    """How well a loop closes: per joint, the jump from the last frame to the next cycle's first
    (frame 0 moved by ``loop_advance``) over that joint's mean per-frame step (``jump_ratio``,
    the worst joint); the root's advance per frame over its mean speed within the cycle."""
    if motion.loop_advance is None:
        raise ShapeMoveError("this motion is not a loop (no loop_advance)")
    J = np.asarray(motion.joints, np.float64)
    T = len(J)
    adv = np.asarray(motion.loop_advance, np.float64)
    jump = np.linalg.norm(J[0] + adv - J[-1], axis=-1)
    step = np.linalg.norm(np.diff(J, axis=0), axis=-1).mean(0)
    ratio = jump / np.maximum(step, 1e-6)
    speed = np.linalg.norm(J[-1, 0, [0, 2]] - J[0, 0, [0, 2]]) / (T - 1)
    per_frame = np.linalg.norm(adv[[0, 2]]) / T
    rel = abs(per_frame / speed - 1.0) if speed > 1e-5 else abs(per_frame) * 1e5
    return {"frames": T, "jump_ratio": float(ratio.max()), "worst_joint": int(ratio.argmax()),
            "advance_m": float(np.linalg.norm(adv[[0, 2]])), "speed_m_per_frame": float(speed),
            "advance_vs_speed": float(rel)}
