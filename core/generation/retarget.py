"""Move a captured motion onto another body: through the SA-VAE (HUMOS-style) or naively.

``retarget(motion, vae, body, betas)``:
  1. read the clip as 22 SMPL joints at 20 fps (BVH, ASF/AMC, AMASS .npz; ``io.mocap.load_smpl22``;
     a ShapeMove motion file's own joints, ``scene.motion_file``) or take a ``Motion22``;
  2. the dataset builder's per-clip steps (``data.build.ClipProcessor``): fit the subject's betas
     to its bone lengths, IK onto that body, the same rotations on the canonical body (betas = 0,
     stride scaled by the pelvis height) -> canonical HumanML3D features;
  3. SA-VAE encode -> motion tokens (searched for: the codes whose decoding on the subject's own
     body comes closest to its motion, ``encode_take``); decode them with the NEW betas -> shape-aware features ->
     joints -> the feet in contact planted, IK onto the new body, the mesh grounded on its soles
     (``decode_tokens``, the generator's decoding), so feet stay planted and bones take the new
     body's lengths. The contacts planted are the SOURCE motion's (``source_contacts``: detected
     on the captured joints, which are known here), not the ones the decoder predicts: a
     retargeted foot stays put exactly where the captured one did. The Motion keeps its tokens:
     ``Generator.redecode`` moves it to yet another body (with the decoder's contacts).
  4. with ``fallback_mm`` (the product's "auto": ``take_fidelity.LOST_TAKE_MM``), first check
     that the codes carry the take: decoded on the subject's own body, their joints within that
     many mm of the take's in its worst second. Where they are not (a fast kick the codec
     flattens), the take is moved by ``planted_retarget`` instead and the Motion says so.
``planted_retarget(arrays, body, betas)``: the subject's rotations on the new body, stride scaled by
leg length, the source's contacts planted and the mesh grounded (no tokens).
``naive_retarget(motion, body, betas)``: the subject's local rotations copied onto the new body,
the root trajectory scaled by the leg-length (pelvis height) ratio, the clip's lowest mesh point put
on the floor (one offset, no contacts). Bones are the new body's, but feet slide, sink and float
wherever the proportions differ. ``ground="frame"`` puts each frame's lowest point on the floor
instead (``ground_each_frame``): no hovering, but nothing keeps a foot planted.
``swap_betas_retarget(motion, body, betas)``: the plainest baseline, the subject's rotations and
translation copied verbatim with the new betas (no scaling, no grounding).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from ..constants import FPS
from ..errors import ShapeMoveError
from ..io.mocap import Motion22
from ..scene.motion_file import Motion, is_motion_file, load_motion, make_motion, validate
from .decode import check_betas, decode_tokens



def savae_checkpoint(path=None) -> Path:
    """A run folder (``savae.pt``, else ``last.pt``), a model folder or a ``.pt`` file -> the
    SA-VAE checkpoint file; None -> the embedded default model's ``savae.pt``."""
    from .model_bundle import DEFAULT_MODEL_DIR

    p = Path(path) if path is not None else DEFAULT_MODEL_DIR / "savae.pt"
    if p.is_dir():
        for name in ("savae.pt", "last.pt"):
            if (p / name).is_file():
                return p / name
        raise ShapeMoveError(f"{p} holds no savae.pt or last.pt: train one with `python -m shapemove train vae`")
    if not p.is_file():
        if path is None:
            raise ShapeMoveError(f"the default model is missing ({p}); pass --checkpoint RUN or rebuild it")
        raise ShapeMoveError(f"checkpoint not found: {p}")
    return p


def load_vae(checkpoint, body):
    """The SA-VAE of ``checkpoint`` (see ``savae_checkpoint``), checked against ``body``."""
    from ..models.savae import load_savae

    return load_savae(savae_checkpoint(checkpoint), body=body)


def source_joints(motion, body=None, read: dict | None = None) -> tuple[np.ndarray, str]:
    """A mocap file path or a ``Motion22`` -> (T,22,3) joints at 20 fps (metres, Y up), name.
    ``read``: the user's overrides of the file's declarations, ``io.mocap.reader_options``
    keywords (``source_fps``, ``angle_unit``)."""
    from ..data.build import MIN_FRAMES
    from ..io.mocap import load_smpl22
    from ..io.resample import resample_positions

    if isinstance(motion, (str, Path)):
        path = Path(motion)
        if not path.is_file():
            raise ShapeMoveError(f"motion file not found: {path}")
        if is_motion_file(path):   # ShapeMove's own motion file: its body's joints, already SMPL-22 at 20 fps
            own = load_motion(path)
            motion = Motion22(own.joints, own.fps, str(path), path.stem, np.zeros((22, 3), np.float32), rig="shapemove")
        else:
            motion = load_smpl22(path, fps=FPS, body_model=body, **(read or {}))
    if not isinstance(motion, Motion22):
        raise ShapeMoveError("retarget needs a motion file (.bvh, .amc, AMASS .npz, a ShapeMove .npz) or a Motion22, "
                             f"got {type(motion).__name__}")
    joints = np.asarray(motion.joints, dtype=np.float64)
    if joints.ndim != 3 or joints.shape[1:] != (22, 3):
        raise ShapeMoveError(f"{motion.source}: joints must be (T,22,3), got {joints.shape}")
    if abs(motion.fps - FPS) > 1e-6:
        joints = resample_positions(joints, motion.fps, FPS)
    if len(joints) < MIN_FRAMES:
        raise ShapeMoveError(f"{motion.source}: too short to retarget ({len(joints)} frames at {FPS} fps, "
                             f"need {MIN_FRAMES})")
    if not np.isfinite(joints).all():
        raise ShapeMoveError(f"{motion.source}: non-finite joint positions")
    return joints.astype(np.float32), str(motion.source)


def processor(body, ik_refine_iters: int = 10):
    from ..data.build import ClipProcessor

    return ClipProcessor(body, ik_refine_iters=ik_refine_iters)


ENCODE_WINDOW = 1024  # feature frames encoded at once (plus the encoder's reach on both sides)


def encoder_reach(vae) -> int:
    """Frames on each side of a token that can change it: the encoder's receptive field (every
    Conv1d's (kernel - 1) * dilation, in input frames), rounded up to whole tokens."""
    reach, jump = 0, 1
    for m in vae.encoder.modules():
        if isinstance(m, torch.nn.Conv1d):
            reach += (m.kernel_size[0] - 1) * m.dilation[0] * jump
            jump *= m.stride[0]
    down = vae.cfg.downsample
    return -(-reach // down) * down


@torch.no_grad()
def encode_latents(vae, x: torch.Tensor, window: int = ENCODE_WINDOW):
    """Normalized features (T,D) (T a multiple of the downsampling) -> the encoders' latents before
    quantization: base (1, T/down, C) and residual (1, T/down, R) (None without a residual code),
    encoded ``window`` frames at a time with ``encoder_reach`` frames of context on each side:
    every step sees what it sees in one pass over the whole take (the same latents), and memory
    stays a constant however long the take."""
    down = vae.cfg.downsample
    window = max(down, window // down * down)
    reach, n = encoder_reach(vae), len(x)
    encoders = [vae.encoder] + ([vae.residual_encoder] if vae.has_residual else [])
    if n <= window + 2 * reach:
        out = [e(x[None]) for e in encoders]
    else:
        parts = [[] for _ in encoders]
        for s in range(0, n, window):
            lo, hi = max(0, s - reach), min(n, s + window + reach)
            for part, e in zip(parts, encoders):
                part.append(e(x[lo:hi][None])[:, (s - lo) // down:(min(n, s + window) - lo) // down])
        out = [torch.cat(part, 1) for part in parts]
    return out[0], (out[1] if vae.has_residual else None)


@torch.no_grad()
def encode_windowed(vae, x: torch.Tensor, window: int = ENCODE_WINDOW) -> torch.Tensor:
    """Normalized features (T,D) -> (T/down,) tokens (``vae.encode_tokens``: the residual packed in
    when the codec has one), from the windowed latents of ``encode_latents``."""
    zb, zr = encode_latents(vae, x, window)
    residual = None if zr is None else vae.residual_quantizer.quantize(zr)
    return vae.tokens_of_codes(vae.quantizer.quantize(zb), residual)[0]


def encode_take(vae, norm_feats, betas=None, shaped_feats=None, search: bool = True, progress=None) -> list[int]:
    """How a take is encoded to be decoded again (retargeting, ``eval recon``, ``eval speed``):
    its canonical features (T,263) -> tokens ((T cut to a multiple of the downsampling) / down).
    With ``search`` and the take's own body (``betas``) and shape-aware features (``shaped_feats``,
    the same frames on that body), the codes are searched for from the encoders' latents
    (``models.code_search``: the codes whose decoding on that body comes closest to the take's
    joints); else the encoders' codes (``encode_windowed``). ``progress(fraction)``."""
    down = vae.cfg.downsample
    n = len(norm_feats) // down * down
    if n == 0:
        raise ShapeMoveError(f"clip too short for the SA-VAE ({len(norm_feats)} feature rows)")
    x = vae.normalize(torch.as_tensor(np.asarray(norm_feats[:n]), dtype=torch.float32))
    if not search or betas is None or shaped_feats is None:
        return [int(i) for i in encode_windowed(vae, x)]
    from ..models.code_search import search_tokens

    if len(shaped_feats) < n:
        raise ShapeMoveError(f"encode_take: {len(shaped_feats)} shape-aware feature rows for {n} canonical ones")
    return [int(i) for i in search_tokens(vae, encode_latents(vae, x), betas, np.asarray(shaped_feats[:n]),
                                          progress=progress)]


def source_contacts(joints) -> np.ndarray:
    """(T,22,3) source joints at 20 fps -> (T,4) uint8 foot contacts of joints 7, 8, 10, 11
    (``motion.contacts.detect_contacts``, as the dataset builder labels its clips)."""
    from ..motion.contacts import detect_contacts

    return detect_contacts(joints, FPS)


def retarget(motion, vae, body, betas, ik_refine_iters: int = 10, plant_source_contacts: bool = True,
             read: dict | None = None, search: bool = True, progress=None, fallback_mm: float | None = None) -> Motion:
    """``motion`` (mocap file path or Motion22) performed by the body ``betas`` (10,), through the
    SA-VAE ``vae`` (trained for ``body``). Returns a validated Motion with tokens: 4*((T-1)//4)
    frames at 20 fps. ``plant_source_contacts``: plant the source's contacts (default) rather
    than the decoder's predicted ones. ``read``: see ``source_joints``. ``search``: the codes
    searched for on the subject's body (``encode_take``; else the encoders'); ``progress(fraction)``
    during the search. ``fallback_mm`` (e.g. ``take_fidelity.LOST_TAKE_MM``): when the codes,
    decoded on the subject's own body, miss the take by more than this in its worst second (the
    codec cannot carry it: a fast kick), the take is moved by ``planted_retarget`` instead (T
    frames, no tokens, a note saying why: ``Motion.notes``); None never falls back."""
    from .take_fidelity import worst_take_error_mm

    betas = check_betas(betas)
    joints, _ = source_joints(motion, body, read)
    arrays = processor(body, ik_refine_iters).process(joints)
    codes = encode_take(vae, arrays["norm_joint_vecs"], arrays["betas"], arrays["new_joint_vecs"], search, progress)
    if fallback_mm is not None:
        worst = worst_take_error_mm(codes, vae, arrays["betas"], arrays["new_joint_vecs"])
        if worst > fallback_mm:
            out = planted_retarget(arrays, body, betas, ik_refine_iters)
            out.notes.append(f"the SA-VAE's codes miss this take by {worst:.0f} mm in its worst second (more than "
                                f"{fallback_mm:g} mm): moved by its own rotations, feet planted, and not "
                                "re-decodable from tokens")
            return out
    out = decode_tokens(codes, vae, body, betas, ik_refine_iters,   # the builder's contacts: source_contacts'
                        contacts=arrays["contacts"] if plant_source_contacts else None)
    validate(out)
    return out


def planted_retarget(arrays: dict, body, betas, ik_refine_iters: int = 10) -> Motion:
    """The subject's own rotations on the body ``betas`` with the take's contacts planted: the
    builder's arrays of the take (``ClipProcessor.process`` on the subject's body: its rotations,
    root and rest joints, its measured contacts) posed on the new body with the stride scaled by
    leg length and grounded on the contacts (``pose_on``), then the feet in contact pinned to one
    point per contact run and IK onto the body (``motion_from_joints``, measured contacts, no
    smoothing: captured joints carry no decoder jitter). T frames, no tokens. Unlike
    ``naive_retarget`` (one offset for the whole clip) no foot slides or floats where the
    proportions differ; unlike the SA-VAE it never loses what the codec cannot carry. Like a
    decoded take it starts with the root over the origin, facing +Z (``start_at_origin``)."""
    from .decode import motion_from_joints

    betas = check_betas(betas)
    contacts = np.asarray(arrays["contacts"], np.uint8)
    shaped = shaped_take(arrays, body, betas, ik_refine_iters)
    out = motion_from_joints(body, betas, shaped, contacts, ik_refine_iters, known_contacts=True, smooth=0.0)
    validate(out)
    return out


def shaped_take(arrays: dict, body, betas, ik_refine_iters: int = 10) -> np.ndarray:
    """(T,22,3) float32 joints of a take's arrays (rotations, root, rest, contacts) posed on the
    body ``betas``: started at the origin facing +Z (``start_at_origin``), the stride scaled by leg
    length and grounded on the take's contacts (``ClipProcessor.pose_on``). What
    ``planted_retarget`` plants, and what a captured part is composed from (``parts.part_of``)."""
    betas = check_betas(betas)
    proc = processor(body, ik_refine_iters)
    rotations, root = start_at_origin(arrays["rotations"], arrays["root"], arrays["rest"])
    return proc.pose_on(rotations, root, betas, proc.stride_scale(arrays["rest"], betas),
                        np.asarray(arrays["contacts"], np.uint8))


def replant(motion: Motion, body, betas, ik_refine_iters: int = 10) -> Motion:
    """A take played by its own rotations (``planted_retarget``'s Motion: measured contacts, no
    tokens) moved onto the body ``betas`` the same way, from what the Motion holds: its local
    rotations, its root path and the rest joints of the body it is on, its planted contacts. The
    stride is scaled by leg length again and the feet planted again, where a body-shape slider alone
    would keep the old stride (the planted feet then slide: 4.1 against 0.5 mm per frame for a
    captured kick moved to a shorter body)."""
    from ..geometry.rotations import axis_angle_to_matrix

    if not motion.planted_take:
        raise ShapeMoveError("only a take played by its own rotations (measured contacts, no motion tokens) is "
                             "re-planted; a motion with tokens is decoded again")
    with torch.no_grad():
        rest = body.rest_joints(torch.as_tensor(np.asarray(motion.betas, np.float32))[None])[0].numpy()
    take = {"rotations": axis_angle_to_matrix(np.asarray(motion.poses, np.float32)),
            "root": np.asarray(motion.transl, np.float32) + rest[0], "rest": rest,
            "contacts": np.asarray(motion.contacts, np.uint8)}
    out = planted_retarget(take, body, betas, ik_refine_iters)
    out.prompt, out.notes, out.provenance = motion.prompt, list(motion.notes), motion.provenance
    if motion.segment_bounds is not None:   # a timeline joined from finished segments keeps its segments
        out.segment_bounds, out.segment_prompts = motion.segment_bounds, motion.segment_prompts
    return out


def start_at_origin(rotations: np.ndarray, root: np.ndarray, rest: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Local rotations (T,24,3,3) and root path (T,3) of a take turned about the vertical and moved
    so that at frame 0 the root is over the origin and the body faces +Z, as every decoded take
    starts (HumanML3D features are relative to the first frame's heading): the facing is read from
    the hips and shoulders across (left minus right) of frame 0 posed on the rest joints ``rest``."""
    from ..body.skeleton import PARENTS
    from ..geometry.fk import forward_kinematics
    from .track import yaw_matrix

    rotations = np.asarray(rotations, np.float64)
    posed = forward_kinematics(rotations[:1], np.asarray(rest, np.float64), PARENTS)[0][0]
    across = (posed[1] - posed[2]) + (posed[16] - posed[17])
    forward = np.cross(across, [0.0, 1.0, 0.0])
    a = -np.arctan2(forward[0], forward[2])            # the turn that brings the facing to +Z
    yaw = yaw_matrix(a)
    out = rotations.copy()
    out[:, 0] = yaw @ rotations[:, 0]
    moved = np.asarray(root, np.float64) - [root[0][0], 0.0, root[0][2]]
    return out.astype(np.float32), (moved @ yaw.T).astype(np.float32)


def swap_betas_retarget(motion, body, betas, ik_refine_iters: int = 10) -> Motion:
    """The plainest retargeting of SMPL-style parameters: the subject's local rotations AND its
    translation (``transl``: FK + transl poses the subject) copied verbatim, only the betas
    swapped (no stride scaling, no grounding: the pelvis keeps the subject's offset from the new
    body's rest pelvis, so a longer-legged body sinks and a shorter one floats). T frames."""
    betas = check_betas(betas)
    joints, _ = source_joints(motion, body)
    sol = processor(body, ik_refine_iters).solve(joints)
    from ..geometry.rotations import matrix_to_axis_angle

    return make_motion(body, matrix_to_axis_angle(sol["rotations"]).astype(np.float32),
                       (sol["root"] - sol["rest"][0]).astype(np.float32), betas, fps=float(FPS))


def naive_retarget(motion, body, betas, ik_refine_iters: int = 10, ground: str = "clip",
                   read: dict | None = None) -> Motion:
    """Local rotations copied from the subject's IK onto the body ``betas``; root trajectory
    scaled by the pelvis-height (leg length) ratio; ``ground`` "clip": the clip's lowest mesh
    point put on the floor (one offset for the whole clip: no contact handling), "frame":
    ``ground_each_frame`` of that. T frames."""
    if ground not in ("clip", "frame"):
        raise ShapeMoveError(f"ground must be 'clip' or 'frame', got {ground!r}")
    betas = check_betas(betas)
    joints, _ = source_joints(motion, body, read)
    proc = processor(body, ik_refine_iters)
    sol = proc.solve(joints)
    shaped = proc.pose_on(sol["rotations"], sol["root"], betas, proc.stride_scale(sol["rest"], betas), None)
    with torch.no_grad():
        rest = body.rest_joints(torch.as_tensor(betas)[None])[0].numpy()
    from ..geometry.rotations import matrix_to_axis_angle

    out = make_motion(body, matrix_to_axis_angle(sol["rotations"]).astype(np.float32), shaped[:, 0] - rest[0], betas,
                      fps=float(FPS))
    return ground_each_frame(out, body) if ground == "frame" else out


def ground_each_frame(motion: Motion, body) -> Motion:
    """``motion`` moved up or down frame by frame so that each frame's lowest mesh point (the body's
    ground probe) is on the floor: it never hovers or sinks, but nothing keeps a foot planted (feet
    slide, heels pop, flights are pressed onto the floor). Poses and XZ path unchanged."""
    from ..body.soles import GroundProbe
    from ..geometry.rotations import axis_angle_to_matrix

    transl = np.asarray(motion.transl, np.float64).copy()
    transl[:, 1] -= GroundProbe(body, motion.betas).lowest(axis_angle_to_matrix(motion.poses), transl)[2]
    return make_motion(body, motion.poses, transl.astype(np.float32), motion.betas, fps=motion.fps)
