"""Which bone of the user's armature plays which SMPL body joint: automatic (presets by name,
else the shape match of ``core.io.skeleton_match``, the engine mocap import uses too) and saved
or loaded as JSON presets. Blender-free: the addon reads the armature into an ``ArmatureRest``.

A bone map is ``{smpl_joint_name: bone_name}`` for any subset of the 22 SMPL body joints
(``SMPL22``); a bone "plays" joint j when its head sits at joint j and it turns with joint j's
rotation (the thigh bone plays the hip joint). Preset files (``rig_presets/*.json`` ship with
ShapeMove; users save their own) hold ``{"format": "shapemove-bone-map", "name": ...,
"bones": {joint: [candidate bone names, first present wins]}}``; names compare exactly, then
case-insensitively without a namespace (``mixamorig1:Hips`` matches ``mixamorig:Hips``).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..atomic import atomic_write_json
from ..body.skeleton import JOINT_NAMES, NUM_BODY_JOINTS
from ..errors import ShapeMoveError
from ..io.limits import read_json
from ..io.rig_map import OPENBODY_LAYOUT, SPINE_JOINTS, normalize
from ..io.skeleton_match import match_humanoid

SMPL22 = tuple(JOINT_NAMES[:NUM_BODY_JOINTS])
PRESET_DIR = Path(__file__).with_name("rig_presets")
PRESET_FORMAT = "shapemove-bone-map"
MAX_PRESET_BYTES = 256 * 1024
# where the body's spine joints sit along the mid-hips -> neck arc (rig_map's body layout)
SPINE_FRACTIONS = {j: f for j, f in zip(SPINE_JOINTS, OPENBODY_LAYOUT.spine) if j != "pelvis"}
# joints a bake cannot do without (root motion, legs for the scale and the feet, arms)
REQUIRED = ("pelvis", "left_hip", "right_hip", "left_knee", "right_knee", "left_ankle", "right_ankle")
TAIL_SUFFIX = "_End"


@dataclass
class ArmatureRest:
    """An armature's rest pose as plain arrays. names (J,); parents (J,) int, -1 for roots,
    parents[j] < j; heads, tails (J,3) and rest_rot (J,3,3) (``Bone.matrix_local``: columns are
    the bone's X, Y (head -> tail), Z axes) in armature space; deform (J,) bool
    (``Bone.use_deform``); matrix_world (4,4) of the armature object."""

    names: list
    parents: np.ndarray
    heads: np.ndarray
    tails: np.ndarray
    rest_rot: np.ndarray
    deform: np.ndarray
    matrix_world: np.ndarray

    def __post_init__(self):
        J = len(self.names)
        self.parents = np.asarray(self.parents, dtype=np.int64).reshape(J)
        self.heads = np.asarray(self.heads, dtype=np.float64).reshape(J, 3)
        self.tails = np.asarray(self.tails, dtype=np.float64).reshape(J, 3)
        self.rest_rot = np.asarray(self.rest_rot, dtype=np.float64).reshape(J, 3, 3)
        self.deform = np.asarray(self.deform, dtype=bool).reshape(J)
        self.matrix_world = np.asarray(self.matrix_world, dtype=np.float64).reshape(4, 4)
        if np.any(self.parents >= np.arange(J)):
            raise ShapeMoveError("armature bones must be listed parents first")
        for name in ("heads", "tails", "rest_rot", "matrix_world"):
            if not np.all(np.isfinite(getattr(self, name))):
                raise ShapeMoveError(f"the armature's {name} are not finite")

    def index(self, name: str) -> int:
        return self.names.index(name)


def _skeleton(arm: ArmatureRest):
    """The joints the shape match sees: deform bones (when the armature also has control bones),
    each reparented to its nearest kept ancestor, plus the tails of the kept leaf bones."""
    keep = arm.deform.copy()
    if keep.sum() < 15 or keep.all():
        keep[:] = True
    idx = {j: k for k, j in enumerate(np.flatnonzero(keep))}
    names, parents, pos = [], [], []
    for j in np.flatnonzero(keep):
        p = int(arm.parents[j])
        while p >= 0 and not keep[p]:
            p = int(arm.parents[p])
        names.append(arm.names[j])
        parents.append(idx[p] if p >= 0 else -1)
        pos.append(arm.heads[j])
    has_child = set(parents)
    for k in range(len(names)):
        if k not in has_child:
            j = arm.index(names[k])
            names.append(names[k] + TAIL_SUFFIX)
            parents.append(k)
            pos.append(arm.tails[j])
    # parents before children (tails were appended after everything)
    return names, np.array(parents), np.array(pos)


def auto_map(arm: ArmatureRest) -> dict:
    """Bone map by the skeleton's shape and name hints (``skeleton_match``); raises
    ShapeMoveError naming the body part it could not find."""
    names, parents, pos = _skeleton(arm)
    rig = match_humanoid(names, parents, pos, rig_name="armature")
    bones = set(arm.names)
    out = {}
    for joint, rule in rig.rules.items():
        if isinstance(rule, str):
            bone = rule
        elif rule[0] == "lerp":
            bone = rule[1]
        else:
            continue
        if bone in bones:
            out[joint] = bone
    spine = [b for b in rig.chain[:-1] if b in bones]
    if spine:
        # the pelvis bone: the one both the legs and the spine hang from (the bake moves it)
        def chain_up(name):
            out_, j = [], arm.index(name)
            while j >= 0:
                out_.append(arm.names[j])
                j = int(arm.parents[j])
            return out_
        above_legs = set(chain_up(out["left_hip"])) & set(chain_up(out["right_hip"])) if "left_hip" in out else set()
        out["pelvis"] = next((b for b in chain_up(spine[0]) if b in above_legs), spine[0])
    out.update(_spine_picks(arm, [b for b in spine if b != out.get("pelvis")], out))
    # a collar that is the chest itself (no clavicle bone) plays no joint of its own
    for side in ("left", "right"):
        if out.get(f"{side}_collar") in (out.get("spine3"), out.get("neck"), out.get("pelvis")):
            out.pop(f"{side}_collar")
    return {j: out[j] for j in SMPL22 if j in out}


def _spine_picks(arm: ArmatureRest, middle, out) -> dict:
    """spine1/2/3 -> the spine bones between the pelvis and the neck whose heads sit nearest the
    body's spine joints along the mid-hips -> neck arc (a rig with fewer spine bones leaves some out)."""
    if not middle or not all(j in out for j in ("left_hip", "right_hip", "neck")):
        return {}
    mid_hips = 0.5 * (arm.heads[arm.index(out["left_hip"])] + arm.heads[arm.index(out["right_hip"])])
    pts = [mid_hips] + [arm.heads[arm.index(b)] for b in [*middle, out["neck"]]]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=-1))])
    if not arc[-1] > 0:
        return {}
    frac = arc[1:-1] / arc[-1]
    best = {}
    for joint, f in SPINE_FRACTIONS.items():
        k = int(np.argmin(np.abs(frac - f)))
        if middle[k] not in best or abs(frac[k] - f) < abs(frac[k] - SPINE_FRACTIONS[best[middle[k]]]):
            best[middle[k]] = joint
    return {joint: bone for bone, joint in best.items()}


def _check_preset(data, source) -> dict:
    if not isinstance(data, dict) or data.get("format") != PRESET_FORMAT or not isinstance(data.get("bones"), dict):
        raise ShapeMoveError(f"{source}: not a ShapeMove bone-map preset (expected a JSON object with "
                             f'"format": "{PRESET_FORMAT}" and "bones")')
    bones = {}
    for joint, cands in data["bones"].items():
        if joint not in SMPL22:
            raise ShapeMoveError(f"{source}: {joint!r} is not an SMPL body joint (use {', '.join(SMPL22[:4])}, ...)")
        cands = [cands] if isinstance(cands, str) else cands
        if not isinstance(cands, list) or not cands or not all(isinstance(c, str) and 0 < len(c) < 256 for c in cands):
            raise ShapeMoveError(f"{source}: the bone names for {joint!r} must be a name or a list of names")
        bones[joint] = list(cands)
    return {"name": str(data.get("name", Path(str(source)).stem))[:100], "description": str(data.get("description", ""))[:300],
            "bones": bones}


def load_preset(path) -> dict:
    """A preset file -> {"name", "description", "bones": {joint: [candidates]}} (validated)."""
    return _check_preset(read_json(path, "bone-map preset", MAX_PRESET_BYTES), Path(path))


def builtin_presets() -> dict:
    """{file stem: preset} of the presets shipped with ShapeMove (Rigify, Mixamo, CC/iClone)."""
    return {p.stem: load_preset(p) for p in sorted(PRESET_DIR.glob("*.json"))}


def find_preset(name_or_path) -> dict:
    """A shipped preset by name (``rigify``, ``mixamo``, ``cc_iclone``) or a preset file."""
    shipped = builtin_presets()
    key = str(name_or_path).lower()
    if key in shipped:
        return shipped[key]
    if Path(name_or_path).suffix.lower() == ".json":
        return load_preset(name_or_path)
    raise ShapeMoveError(f"unknown bone-map preset {name_or_path!r}: use one of {', '.join(shipped)} or a .json file")


def save_preset(path, mapping: dict, name: str, description: str = "") -> Path:
    """Write a bone map as a preset (atomic)."""
    bad = [j for j in mapping if j not in SMPL22]
    if bad:
        raise ShapeMoveError(f"not SMPL body joints: {', '.join(bad)}")
    data = {"format": PRESET_FORMAT, "version": 1, "name": str(name), "description": str(description),
            "bones": {j: [mapping[j]] for j in SMPL22 if mapping.get(j)}}
    path = atomic_write_json(path, data, indent=1)
    return path


def apply_preset(preset: dict, bone_names) -> dict:
    """Bone map of ``preset`` on an armature with ``bone_names`` (joints whose bones are absent
    are left out)."""
    exact = set(bone_names)
    loose = {}
    for b in bone_names:
        loose.setdefault(normalize(b), b)
    out = {}
    for joint in SMPL22:
        for cand in preset["bones"].get(joint, ()):
            hit = cand if cand in exact else loose.get(normalize(cand))
            if hit is not None:
                out[joint] = hit
                break
    return out


def best_preset(bone_names, min_joints: int = 18):
    """(preset key, bone map) of the shipped preset that maps the most joints, if it maps at least
    ``min_joints`` of them and all of ``REQUIRED``; else (None, {})."""
    best = (None, {})
    for key, preset in builtin_presets().items():
        m = apply_preset(preset, bone_names)
        if len(m) >= min_joints and all(j in m for j in REQUIRED) and len(m) > len(best[1]):
            best = (key, m)
    return best


def map_armature(arm: ArmatureRest, preset=None) -> tuple[dict, str]:
    """(bone map, how it was found): the given preset (name, path or dict), else the best
    shipped preset, else the shape match."""
    if preset is not None:
        p = preset if isinstance(preset, dict) else find_preset(preset)
        m = apply_preset(p, arm.names)
        check_map(m, arm.names)
        return m, f"preset {p['name']}"
    key, m = best_preset(arm.names)
    if key is not None:
        return m, f"preset {builtin_presets()[key]['name']}"
    return auto_map(arm), "matched by shape"


def check_map(mapping: dict, bone_names) -> None:
    """Raise ShapeMoveError when a bone map misses a required joint, names an absent bone or
    uses one bone twice."""
    have = set(bone_names)
    absent = [f"{j} -> {b}" for j, b in mapping.items() if b not in have]
    if absent:
        raise ShapeMoveError(f"the armature has no bones {', '.join(absent)}: fix the bone map")
    missing = [j for j in REQUIRED if not mapping.get(j)]
    if missing:
        raise ShapeMoveError(f"the bone map does not say which bones play {', '.join(missing)}: "
                             "pick them in the bone map or load a preset")
    used = {}
    for j, b in mapping.items():
        if b in used:
            raise ShapeMoveError(f"bone {b!r} plays both {used[b]} and {j}: each bone may play one joint")
        used[b] = j
