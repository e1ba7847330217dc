"""Two things at once, and the named side, at generation time: motions put together by body part.

A prompt such as "a woman jogs along, waving her left hand" asks for two motions at once: the legs
and root of a jog and the arms of a wave. ``part_prompts.plan_parts`` splits it into a legs
prompt and an arms prompt; each is generated on its own (the model does single actions far better
than pairs), then put together here on the decoder's joint tracks, before the feet are planted:

- ``compose_arms``: the collars and shoulders of the arms track, carried in their chest's frame
  onto the legs track's chest (spine3 at the origin, the spine's up and the collars' left-right as
  axes), so they sit on the walker's torso however it leans; the upper arms and forearms (elbows,
  wrists) then keep the direction they have in the gesture clip relative to its heading and the
  vertical (``heading_frames``), turned to the walker's heading: a hand raised straight up stays
  straight up on a runner leaning forward, arms that hang stay hanging on a crouched sneak.
  Carried in the chest's frame instead, they tipped forward with the torso, and the judge by part
  read a reach up or a wave on a run as no gesture (tuning two-things prompts: arms right 50.0 ->
  59.4 %; held-out: 34.4 -> 40.6 %). Everything else (root, legs, spine, head) and the foot
  contacts are the legs track's. The dataset's ``data/compose_parts.py`` builds its training
  clips with local rotations instead, the arms' in the chest's frame.
- ``side_activity`` / ``mirror_track``: a prompt that names a side ("kicks with the left foot")
  whose motion moves the other side more is mirrored (``data/mirror.py``: x negated, left and right
  joints and contacts swapped; the body model is symmetric), so the named side moves most.

Both edits keep every frame of the tracks and end, like every other edit, in ``plant``: one fixed
foothold per contact run, IK onto the body, the mesh grounded on its soles.
"""
from __future__ import annotations

import numpy as np

from ..data.mirror import mirror_contacts, mirror_joints
from ..errors import ShapeMoveError

SPINE1, CHEST = 3, 9
LEFT_COLLAR, RIGHT_COLLAR = 13, 14
ARM_JOINTS = [13, 14, 16, 17, 18, 19, 20, 21]   # collars, shoulders, elbows, wrists (22-joint track)
GIRDLE = [13, 14, 16, 17]                        # collars and shoulders: carried in the chest's frame
LIMBS = [(18, 16), (19, 17), (20, 18), (21, 19)]  # (joint, parent): upper arms, then forearms
# the joints whose travel says which side moves: (left, right); hand = elbow + wrist, foot = ankle + foot
SIDE_JOINTS = {"hand": ([18, 20], [19, 21]), "foot": ([7, 10], [8, 11])}


def _check(joints, what: str) -> np.ndarray:
    j = np.asarray(joints, np.float64)
    if j.ndim != 3 or j.shape[1:] != (22, 3) or len(j) < 2 or not np.isfinite(j).all():
        raise ShapeMoveError(f"{what}: need finite (T>=2,22,3) joints, got {np.shape(joints)}")
    return j


def chest_frames(joints) -> np.ndarray:
    """(T,3,3) orthonormal frames of the chest, columns (left, up, forward): up along spine1 ->
    spine3, left from the right collar to the left one, made orthogonal to up."""
    j = _check(joints, "chest frames")
    up = j[:, CHEST] - j[:, SPINE1]
    up /= np.maximum(np.linalg.norm(up, axis=-1, keepdims=True), 1e-9)
    left = j[:, LEFT_COLLAR] - j[:, RIGHT_COLLAR]
    left -= (left * up).sum(-1, keepdims=True) * up
    n = np.linalg.norm(left, axis=-1, keepdims=True)
    if (n < 1e-6).any():
        raise ShapeMoveError("chest frames: the collars coincide with the spine's axis in some frame")
    left /= n
    fwd = np.cross(left, up)
    return np.stack([left, up, fwd], axis=-1)


def heading_frames(joints, chest: np.ndarray | None = None) -> np.ndarray:
    """(T,3,3) frames columns (left, up, forward) with up the world's vertical (+Y) and left the
    collars' left-right on the floor: the body's heading, not its lean. Where the collar line is
    within ~12 degrees of vertical (a body on its side) the chest's own frame stands in.
    ``chest``: the joints' ``chest_frames`` when already computed."""
    chest = chest_frames(joints) if chest is None else chest
    left = chest[:, :, 0].copy()
    left[:, 1] = 0.0
    n = np.linalg.norm(left, axis=-1, keepdims=True)
    level = n[:, 0] >= 0.2
    left = left / np.maximum(n, 1e-9)
    up = np.broadcast_to(np.array([0.0, 1.0, 0.0]), left.shape)
    out = np.stack([left, up, np.cross(left, up)], axis=-1)
    out[~level] = chest[~level]
    return out


def compose_arms(legs_joints, arms_joints) -> np.ndarray:
    """(T,22,3) joints: the legs track with the arms track's arm joints (``ARM_JOINTS``) put on its
    chest (module docstring): collars and shoulders in the chest's frame, each upper arm and forearm
    with its direction in the heading frame. Both tracks must have the same length (generate the
    arms for the legs' length); bone lengths are the arms track's."""
    a, b = _check(legs_joints, "compose: legs track"), _check(arms_joints, "compose: arms track")
    if len(a) != len(b):
        raise ShapeMoveError(f"compose: the legs track has {len(a)} frames and the arms track {len(b)}; "
                             "they must be as long")
    out = a.copy()
    ra, rb = chest_frames(a), chest_frames(b)
    rel = b[:, GIRDLE] - b[:, CHEST:CHEST + 1]                             # (T,4,3) world, about b's chest
    local = np.einsum("tji,tkj->tki", rb, rel)                              # in b's chest frame: R_b^T p
    out[:, GIRDLE] = a[:, CHEST:CHEST + 1] + np.einsum("tij,tkj->tki", ra, local)
    ha, hb = heading_frames(a, ra), heading_frames(b, rb)
    for joint, parent in LIMBS:   # parents first: each segment hangs from its already placed parent
        seg = np.einsum("tji,tj->ti", hb, b[:, joint] - b[:, parent])      # in b's heading frame
        out[:, joint] = out[:, parent] + np.einsum("tij,tj->ti", ha, seg)
    return out


def side_activity(joints, part: str) -> tuple[float, float]:
    """(left, right): how far the part's joints travel relative to the pelvis over the clip, in
    metres (the world's axes, no turning removed). ``part``: "hand" or "foot"."""
    if part not in SIDE_JOINTS:
        raise ShapeMoveError(f"side: part must be one of {', '.join(SIDE_JOINTS)}, got {part!r}")
    j = _check(joints, "side")
    rel = j - j[:, :1]
    step = np.linalg.norm(np.diff(rel, axis=0), axis=-1).sum(0)
    left, right = SIDE_JOINTS[part]
    return float(step[left].sum()), float(step[right].sum())


def needs_mirror(joints, side: str, part: str) -> bool:
    """Whether the side that moves most is not the named one (so the mirror image is wanted)."""
    if side not in ("left", "right"):
        raise ShapeMoveError(f"side must be 'left' or 'right', got {side!r}")
    left, right = side_activity(joints, part)
    return (left < right) if side == "left" else (right < left)


def mirror_track(joints, contacts) -> tuple[np.ndarray, np.ndarray]:
    """The mirror image of a track: (joints, contacts) with left and right swapped, x negated."""
    j = _check(joints, "mirror")
    c = np.asarray(contacts)
    if c.shape != (len(j), 4):
        raise ShapeMoveError(f"mirror: need ({len(j)},4) contacts, got {c.shape}")
    return mirror_joints(j), mirror_contacts(c)
