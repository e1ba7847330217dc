"""Map a mocap skeleton onto the 22 SMPL body joints (HumanML3D order) by joint POSITION.

Every SMPL joint is a fixed linear combination of source joint positions, so a whole clip maps
with one matrix product: ``smpl22 = W @ source`` with W (22, J). A rule is one of

- ``"Name"``: the source joint itself (knees, ankles, shoulders, elbows, wrists, neck, head);
- ``("lerp", "A", "B", t)``: (1-t)*A + t*B (CMU clavicles start on the mid-line: the SMPL collar
  sits ~45% of the way to the shoulder);
- ``("chain", k)``: spine joint k (pelvis, spine1, spine2, spine3) at the body's fraction of the
  arc length of the rig's spine chain, which runs from the midpoint of the two hip joints up the
  rig's spine joints to the neck.

The joints a rig has no counterpart for are placed with the BODY's layout (``BodyLayout``), so the
mapped skeleton has the proportions of the body the motion is retargeted onto (OpenBody,
``OPENBODY_LAYOUT``, measured on its mean rest joints by ``body_layout``): pelvis, spine1, spine2
and spine3 at the body's fractions of the mid-hips -> neck arc (``DEFAULT_LAYOUT``), and
optionally the hip joints spread sideways about the mid-hips point to the body's hip width for the
clip's leg length (mocap rigs put the hip joints 6-11 cm from the mid-line, OpenBody 11 cm at 81 cm
of leg). With the full OpenBody layout a body whose bone lengths fit the clip reproduces it to
~0.6 cm; with the legacy SMPL fractions (``SMPL_LAYOUT``) the spine alone cost 2-4 cm. For rigs
whose neck, head or clavicle joints sit far from the body's (``ANCHORED``: Bandai, Daz), those
joints slide along the rig's bones to the body's upper-body proportions (``BodyLayout.upper``).

Left means the subject's left (SMPL/HumanML3D: left hip at +X when the body faces +Z).
Source names are compared case-insensitively after dropping a namespace (``mixamorig:Hips``).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..body.skeleton import JOINT_NAMES, NUM_BODY_JOINTS
from ..errors import ShapeMoveError
from .rig import SPINE_JOINTS, Rig, normalize
from .skeleton_match import match_humanoid

SMPL22 = JOINT_NAMES[:NUM_BODY_JOINTS]


@dataclass(frozen=True)
class BodyLayout:
    """Where a body model keeps the joints mocap rigs lack. ``spine``: fractions of the mid-hips
    -> pelvis -> spine1 -> spine2 -> spine3 -> neck arc for the four SPINE_JOINTS; ``hip_width``:
    half the distance between the hip joints divided by the leg length (hip -> knee -> ankle),
    or None to keep the rig's own hip joints."""

    spine: tuple
    hip_width: float | None = None
    # (neck, head, collar_up, collar_half) as fractions of the torso (mid-hips -> mid-shoulders):
    # neck above the mid-shoulders, head joint above the neck, the collars' midpoint up the
    # mid-shoulders -> neck line, each collar sideways from it; used for the rigs in ANCHORED
    upper: tuple | None = None


# OpenBody's mean rest joints (assets/openbody.npz; tests check these against ``body_layout``)
OPENBODY_LAYOUT = BodyLayout(spine=(0.032, 0.300, 0.445, 0.669), hip_width=0.138, upper=(0.211, 0.223, 0.300, 0.142))
# what ``mapping_matrix`` / ``mocap.load_smpl22`` use: OpenBody's spine and upper body, the rig's own
# hip joints (so the mapped thigh stays the source's thigh bone; pass OPENBODY_LAYOUT for the hip width too)
DEFAULT_LAYOUT = BodyLayout(spine=OPENBODY_LAYOUT.spine, hip_width=None, upper=OPENBODY_LAYOUT.upper)
# the approximate neutral-SMPL fractions used before (hips 0.09 below the pelvis, neck 0.51 above)
SMPL_LAYOUT = BodyLayout(spine=(0.15, 0.34, 0.56, 0.64), hip_width=None)
SPINE_FRACTIONS = dict(zip(SPINE_JOINTS, OPENBODY_LAYOUT.spine))
# rigs whose neck / head / collar joints are only loosely where the body's are: those SMPL joints
# are moved along the rig's own bones to the layout's ``upper`` proportions of the well-defined
# hips and shoulders (``_anchor_upper``). Measured on real clips (``bench ik``, the builder's fit):
# Bandai's Neck sits ~5 cm low and its Head ~4 cm off, Daz's Neck ~5 cm low and its lCollar near
# the mid-line; anchoring them lowers the IK error on OpenBody (Bandai 2.37 -> 1.94 cm, CMU 1.74
# -> 1.60) and that of the well-defined joints too (the body fit is no longer pulled by them).
# ASF rigs (HDM05, CMU) keep their own joints: anchoring did not help there.
ANCHORED = {"bandai": ("neck", "head", "collar"), "daz": ("neck", "collar")}


def body_layout(rest_joints) -> BodyLayout:
    """The BodyLayout of a body's rest joints (22 or 24, 3) in SMPL order, metres."""
    j = np.asarray(rest_joints, dtype=np.float64).reshape(-1, 3)
    if j.shape[0] < NUM_BODY_JOINTS or not np.all(np.isfinite(j)):
        raise ShapeMoveError(f"rest joints must be (22,3) or (24,3) finite values, got {np.shape(rest_joints)}")
    pts = np.stack([(j[1] + j[2]) / 2, j[0], j[3], j[6], j[9], j[12]])
    cum = np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=-1))
    leg = (np.linalg.norm(j[4] - j[1]) + np.linalg.norm(j[7] - j[4]) + np.linalg.norm(j[5] - j[2])
           + np.linalg.norm(j[8] - j[5])) / 2
    mid_s, mid_h = (j[16] + j[17]) / 2, (j[1] + j[2]) / 2
    torso = np.linalg.norm(mid_s - mid_h)
    neck = np.linalg.norm(j[12] - mid_s)
    up = float(np.dot((j[13] + j[14]) / 2 - mid_s, j[12] - mid_s) / neck ** 2)
    upper = (neck / torso, np.linalg.norm(j[15] - j[12]) / torso, up, np.linalg.norm(j[13] - j[14]) / 2 / torso)
    return BodyLayout(spine=tuple(float(c) for c in cum[:4] / cum[-1]),
                      hip_width=float(np.linalg.norm(j[1] - j[2]) / 2 / leg), upper=tuple(float(u) for u in upper))


def _limbs(hip, knee, ankle, foot, collar, shoulder, elbow, wrist):
    """Rules for both sides from name templates: '{s}' -> l/r, '{S}' -> Left/Right, '{X}' -> L/R."""
    out = {}
    for side, s in (("left", "L"), ("right", "R")):
        for smpl, tmpl in (("hip", hip), ("knee", knee), ("ankle", ankle), ("foot", foot),
                           ("collar", collar), ("shoulder", shoulder), ("elbow", elbow), ("wrist", wrist)):
            out[f"{side}_{smpl}"] = _side(tmpl, s)
    return out


def _side(rule, s):
    sides = {"L": ("l", "Left", "L"), "R": ("r", "Right", "R")}[s]
    fill = lambda name: name.format(s=sides[0], S=sides[1], X=sides[2])  # noqa: E731
    if isinstance(rule, str):
        return fill(rule)
    return tuple(fill(x) if isinstance(x, str) else x for x in rule)


def _rig(name, chain, neck, head, limbs, optional=()):
    rules = dict(limbs)
    rules["neck"] = neck
    rules["head"] = head
    for k, joint in enumerate(SPINE_JOINTS):
        rules[joint] = ("chain", k)  # index into BodyLayout.spine
    return Rig(name, rules, tuple(chain) + (neck,), neck, head, tuple(optional))


RIGS = [
    # SMPL itself (AMASS): identity
    Rig("smpl", {n: n for n in SMPL22}, (), "neck", "head"),
    _rig("bandai", ("Hips", "Spine", "Chest"), "Neck", "Head",
         _limbs("UpperLeg_{X}", "LowerLeg_{X}", "Foot_{X}", "Toes_{X}",
                "Shoulder_{X}", "UpperArm_{X}", "LowerArm_{X}", "Hand_{X}")),
    # ASF bones, each placed at its START (see asf_amc): lfemur = hip joint, ltoes = ball of foot
    _rig("cmu_asf", ("root", "upperback", "thorax", "lowerneck"), "upperneck", "head",
         _limbs("{s}femur", "{s}tibia", "{s}foot", "{s}toes",
                ("lerp", "{s}clavicle", "{s}humerus", 0.45), "{s}humerus", "{s}radius", "{s}wrist")),
    # cgspeed's BVH conversion of CMU (same joints as the ASF, BVH names)
    _rig("cmu_cgspeed", ("Hips", "Spine", "Spine1", "Neck"), "Neck1", "Head",
         _limbs("{S}UpLeg", "{S}Leg", "{S}Foot", "{S}ToeBase",
                ("lerp", "{S}Shoulder", "{S}Arm", 0.45), "{S}Arm", "{S}ForeArm", "{S}Hand")),
    # Daz/Poser-style rig of the CMU BVH release (lFoot's End Site is the ball of the foot)
    _rig("daz", ("abdomen", "chest"), "neck", "head",
         _limbs("{s}Thigh", "{s}Shin", "{s}Foot", "{s}Foot_End",
                "{s}Collar", "{s}Shldr", "{s}ForeArm", "{s}Hand")),
    _rig("mixamo", ("Hips", "Spine", "Spine1", "Spine2"), "Neck", "Head",
         _limbs("{S}UpLeg", "{S}Leg", "{S}Foot", "{S}ToeBase",
                "{S}Shoulder", "{S}Arm", "{S}ForeArm", "{S}Hand"),
         optional=("Hips", "Spine", "Spine1", "Spine2")),
    # DeepMimic humanoid3d (io/deepmimic: root between the hips; head and toes are its virtual points)
    _rig("deepmimic", ("root", "chest"), "neck", "head",
         _limbs("{S}_hip", "{S}_knee", "{S}_ankle", "{S}_toe",
                ("lerp", "neck", "{S}_shoulder", 0.45), "{S}_shoulder", "{S}_elbow", "{S}_wrist")),
]


def _rule_names(rule) -> list[str]:
    if isinstance(rule, str):
        return [rule]
    if rule[0] == "lerp":
        return [rule[1], rule[2]]
    return []


def _required(rig: Rig) -> dict:
    """SMPL joint -> source names it needs (chain joints need the whole non-optional chain)."""
    chain_needs = [n for n in rig.chain if n not in rig.optional]
    chain_needs += [rig.rules["left_hip"], rig.rules["right_hip"]] if rig.chain else []
    return {j: chain_needs if isinstance(r, tuple) and r[0] == "chain" else _rule_names(r)
            for j, r in rig.rules.items()}


def find_rig(names, parents=None, rest=None) -> Rig | None:
    """The first rig whose every rule resolves against ``names``, else None. With ``parents``
    (J,) and ``rest`` (J,3) rest positions (or (K,J,3) poses to try, ``pose_candidates``), a
    skeleton absent from the tables is matched by its shape (``skeleton_match.match_humanoid``);
    None when that fails too."""
    rig = _find_rig(tuple(names))
    if rig is None and parents is not None and rest is not None:
        try:
            rig = _match(names, parents, rest)
        except ShapeMoveError:
            return None
    return rig


def pose_candidates(rest, positions) -> np.ndarray:
    """(K,J,3) poses to match an unknown skeleton on: its rest pose, then its first and middle
    frames (for rigs whose offsets do not stand, the motion does)."""
    positions = np.asarray(positions, dtype=np.float64)
    picks = [np.asarray(rest, dtype=np.float64)] + ([positions[0], positions[len(positions) // 2]] if len(positions) else [])
    return np.stack(picks)


def _match(names, parents, rest) -> Rig:
    return match_humanoid(names, parents, rest)


@lru_cache(maxsize=256)
def _find_rig(names: tuple) -> Rig | None:
    have = {normalize(n) for n in names}
    for rig in RIGS:
        if all(normalize(n) in have for needs in _required(rig).values() for n in needs):
            return rig
    return None


def detect_rig(names, parents=None, rest=None) -> Rig:
    """Like ``find_rig`` but raises ShapeMoveError: for a skeleton given by names only, listing the
    SMPL joints that could not be mapped (for the rig that came closest); with ``parents`` and
    ``rest``, saying which body part the shape match could not find."""
    rig = _find_rig(tuple(names))
    if rig is not None:
        return rig
    if parents is not None and rest is not None:
        try:
            return _match(names, parents, rest)
        except ShapeMoveError as exc:
            raise ShapeMoveError(f"unknown skeleton ({len(names)} joints, not a rig in the tables): {exc}") from None
    have = {normalize(n) for n in names}
    best, best_missing = None, None
    for cand in RIGS:
        missing = [j for j, needs in _required(cand).items() if any(normalize(n) not in have for n in needs)]
        if best_missing is None or len(missing) < len(best_missing):
            best, best_missing = cand, missing
    missing = [j for j in SMPL22 if j in best_missing]
    raise ShapeMoveError(
        f"unknown skeleton: cannot map SMPL joints {', '.join(missing)} "
        f"(closest known rig: {best.name}; joints in file: {', '.join(list(names)[:12])}"
        f"{', ...' if len(names) > 12 else ''})")


def mapping_matrix(rig: Rig, names, positions: np.ndarray, layout: BodyLayout = DEFAULT_LAYOUT) -> np.ndarray:
    """W (22, J) such that ``W @ positions[t]`` is the SMPL22 skeleton at frame t.

    ``positions`` (T,J,3) fixes the spine-chain segment lengths and the leg length (medians over
    frames, so it works whatever the rig's rest pose is); ``layout``: the target body's layout."""
    index = {normalize(n): i for i, n in enumerate(names)}
    J = len(names)

    def onehot(name):
        w = np.zeros(J)
        w[index[normalize(name)]] = 1.0
        return w

    def rule_weights(rule):
        if isinstance(rule, str):
            return onehot(rule)
        if rule[0] == "lerp":
            return (1 - rule[3]) * onehot(rule[1]) + rule[3] * onehot(rule[2])
        raise AssertionError(rule)

    W = np.zeros((len(SMPL22), J))
    for i, joint in enumerate(SMPL22):
        rule = rig.rules[joint]
        if not (isinstance(rule, tuple) and rule[0] == "chain"):
            W[i] = rule_weights(rule)
    if not rig.chain:
        return W

    def median_length(w):  # median over frames of |w @ positions|
        return float(np.median(np.linalg.norm(np.matmul(w, positions), axis=-1)))

    mid = 0.5 * (W[1] + W[2])
    pts = np.stack([mid] + [onehot(n) for n in rig.chain if normalize(n) in index])  # (K,J)
    seg = np.array([median_length(b - a) for a, b in zip(pts[:-1], pts[1:])])       # (K-1,)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    if not cum[-1] > 0:
        raise ShapeMoveError(f"degenerate skeleton: the spine chain of the {rig.name} rig has zero length")
    for i, joint in enumerate(SMPL22):
        rule = rig.rules[joint]
        if isinstance(rule, tuple) and rule[0] == "chain":
            s = layout.spine[rule[1]] * cum[-1]
            k = int(np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1))
            t = 0.0 if seg[k] <= 0 else (s - cum[k]) / seg[k]
            W[i] = (1 - t) * pts[k] + t * pts[k + 1]
    if layout.hip_width is not None:
        # spread (or narrow) the hip joints about the mid-hips point to the body's hip width
        leg = sum(median_length(W[c] - W[p]) for p, c in ((1, 4), (4, 7), (2, 5), (5, 8))) / 2
        half = median_length(W[1] - W[2]) / 2
        if half > 1e-3 * leg:
            scale = float(np.clip(layout.hip_width * leg / half, 0.5, 2.5))
            W[1], W[2] = mid + scale * (W[1] - mid), mid + scale * (W[2] - mid)
    if layout.upper is not None and rig.name in ANCHORED:
        _anchor_upper(W, ANCHORED[rig.name], layout.upper, positions)
    return W


def _anchor_upper(W, joints, upper, positions):
    """Move the neck / head / collars (rows of W, in place) to the layout's ``upper`` fractions of
    the torso (mid-hips -> mid-shoulders): the neck ~ along the torso above the mid-shoulders, the
    head joint above it, the collars about a point on the mid-shoulders -> neck line, along the
    shoulder line. Each stays on its rig bone (neck and head on the rig's neck -> head line, a
    collar on the rig's clavicle -> shoulder line) at one per-clip fraction fitted by least squares
    over the frames, so the mapped bones stay as rigid as the rig's."""
    f_neck, f_head, f_up, f_half = upper
    P = np.asarray(positions, dtype=np.float64)
    at = lambda w: np.matmul(w, P)  # noqa: E731
    med = lambda w: float(np.median(np.linalg.norm(at(w), axis=-1)))  # noqa: E731

    def along(a, b, goal):  # a + t (b - a), t fitted to ``goal`` over the frames
        d = at(b - a)
        den = float(np.sum(d * d))
        t = float(np.sum(d * (at(goal) - at(a)))) / den if den > 0 else 0.0
        t = float(np.clip(t, -1.0, 2.0))  # stays near the rig's bone, whatever the clip
        return a + t * (b - a)

    S, H = 0.5 * (W[16] + W[17]), 0.5 * (W[1] + W[2])
    torso = med(S - H)
    if not torso > 0:
        raise ShapeMoveError("degenerate skeleton: the hip and shoulder joints coincide")
    neck0, head0 = W[12].copy(), W[15].copy()
    span = med(head0 - neck0)
    if "neck" in joints and span > 0:
        W[12] = along(neck0, head0, S + f_neck * (S - H))
    if "head" in joints and span > 0:
        W[15] = W[12] + (f_head * torso / span) * (head0 - neck0)
    if "collar" in joints:
        half = 0.5 * (W[16] - W[17])
        k = f_half * torso / max(med(half), 1e-12)
        C = S + f_up * (W[12] - S)
        W[13] = along(W[13], W[16], C + k * half)
        W[14] = along(W[14], W[17], C - k * half)


def map_positions(names, positions: np.ndarray, rig: Rig | None = None,
                  layout: BodyLayout = DEFAULT_LAYOUT) -> tuple[np.ndarray, Rig]:
    """(T,J,3) source positions -> ((T,22,3) SMPL22 positions, rig used)."""
    rig = rig or detect_rig(names)
    W = mapping_matrix(rig, names, positions, layout)
    return np.matmul(W, positions), rig
