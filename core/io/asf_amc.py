"""Acclaim ASF (skeleton) + AMC (motion) reader, as used by CMU and HDM05.

ASF ``:units``: ``length L`` means file lengths are in units of 1/L inches (CMU/HDM05: 0.45), so
metres = value / L * 0.0254; ``angle deg|rad``. Each bone has a direction and length in the rest
pose, an ``axis`` frame C (Euler angles + order) and ``dof`` channels; its pose is
``W_bone = W_parent @ C @ M(dof values) @ C^-1`` and its end lies at ``start + length * W_bone @ dir``.
Euler orders compose in the listed order about fixed axes (``XYZ`` -> Rz @ Ry @ Rx).

In the returned Mocap every bone is a joint placed at the bone's START (so ``lfemur`` is the hip
joint, ``ltibia`` the knee, ``ltoes`` the ball of the foot); leaf bones get an End Site joint
``<bone>_End`` at their tip. AMC files carry no frame rate: CMU and HDM05 are 120 fps
(``HDM_.._120.amc``: the suffix is read).
"""
from __future__ import annotations

import re
from array import array
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from ..geometry.fk import forward_kinematics, joints_from_offsets
from ..geometry.rotations import euler_matrix
from .limits import (MAX_AMC_BYTES, MAX_FRAME_TIME, MAX_HIERARCHY_BYTES, MAX_JOINT_FRAMES, MIN_FRAME_TIME,
                     check_joint_frames, is_number, open_bounded, read_text)
from .mocap_clip import Mocap, finish_mocap
from .rig_map import find_rig

INCH = 0.0254
MAX_VALUE = 1e7
MAX_BONES = 1000


@dataclass
class Bone:
    name: str
    direction: np.ndarray = field(default_factory=lambda: np.zeros(3))
    length: float = 0.0
    axis: np.ndarray = field(default_factory=lambda: np.zeros(3))
    axis_order: str = "XYZ"
    dof: list = field(default_factory=list)


@dataclass
class Skeleton:
    """A parsed ASF: bones by name, children lists, root channel order and axis order,
    metres per length unit and radians per angle unit."""

    bones: dict
    children: dict
    root_order: list
    root_axis: str
    root_position: np.ndarray
    root_orientation: np.ndarray
    length_scale: float
    angle_scale: float
    source: str = ""


def fixed_axes_matrix(order: str, angles) -> np.ndarray:
    """Rotation about fixed axes applied in ``order`` (e.g. 'XYZ' -> Rz @ Ry @ Rx); angles (...,3)
    radians given in X,Y,Z slots."""
    outer_first = order.upper()[::-1]  # the last rotation applied is the outermost factor
    return euler_matrix(outer_first.lower(), np.asarray(angles, dtype=np.float64)[..., ["XYZ".index(a) for a in outer_first]])


def _floats(parts, n, what, source):
    if len(parts) < n:
        raise ShapeMoveError(f"{source}: ASF {what} needs {n} numbers")
    try:
        vals = np.array([float(p) for p in parts[:n]])
    except ValueError:
        raise ShapeMoveError(f"{source}: ASF {what}: not a number in {' '.join(parts)[:60]!r}") from None
    if not np.all(np.isfinite(vals)) or np.abs(vals).max(initial=0) > MAX_VALUE:
        raise ShapeMoveError(f"{source}: ASF {what}: value not finite")
    return vals


def _order(s: str, source) -> str:
    s = s.upper()
    if sorted(s) != ["X", "Y", "Z"]:
        raise ShapeMoveError(f"{source}: ASF rotation order {s[:10]!r} is not a permutation of XYZ")
    return s


def parse_asf(text: str, source="ASF") -> Skeleton:
    bones, children, listed = {}, {}, set()
    root_order, root_axis = ["TX", "TY", "TZ", "RX", "RY", "RZ"], "XYZ"
    root_pos, root_ori = np.zeros(3), np.zeros(3)
    length_unit, angle_deg = 1.0, True
    section, bone = None, None
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.split()
        key = parts[0].lower()
        if key.startswith(":"):
            section = key
            continue
        if section == ":units":
            if key == "length":
                length_unit = float(_floats(parts[1:], 1, "units length", source)[0])
                if length_unit <= 0:
                    raise ShapeMoveError(f"{source}: ASF units length must be positive")
            elif key == "angle":
                if len(parts) < 2 or parts[1].lower() not in ("deg", "rad"):
                    raise ShapeMoveError(f"{source}: ASF units angle must be deg or rad")
                angle_deg = parts[1].lower() == "deg"
        elif section == ":root":
            if key == "order":
                root_order = [p.upper() for p in parts[1:]]
                bad = [p for p in root_order if p not in ("TX", "TY", "TZ", "RX", "RY", "RZ")]
                if bad or len(set(root_order)) != len(root_order):
                    raise ShapeMoveError(f"{source}: ASF root order {' '.join(parts[1:])[:60]!r} is not valid")
            elif key == "axis":
                root_axis = _order(parts[1] if len(parts) > 1 else "", source)
            elif key == "position":
                root_pos = _floats(parts[1:], 3, "root position", source)
            elif key == "orientation":
                root_ori = _floats(parts[1:], 3, "root orientation", source)
        elif section == ":bonedata":
            if key == "begin":
                bone = Bone("")
            elif key == "end":
                if bone is None or not bone.name:
                    raise ShapeMoveError(f"{source}: ASF bone block without a name")
                if bone.name in bones or bone.name == "root":
                    raise ShapeMoveError(f"{source}: ASF bone {bone.name!r} defined twice")
                if len(bones) >= MAX_BONES:
                    raise ShapeMoveError(f"{source}: ASF has more than {MAX_BONES} bones")
                bones[bone.name] = bone
                bone = None
            elif bone is not None:
                if key == "name" and len(parts) > 1:
                    bone.name = parts[1]
                elif key == "direction":
                    bone.direction = _floats(parts[1:], 3, "direction", source)
                elif key == "length":
                    bone.length = float(_floats(parts[1:], 1, "length", source)[0])
                elif key == "axis":
                    bone.axis = _floats(parts[1:], 3, "axis", source)
                    bone.axis_order = _order(parts[4] if len(parts) > 4 else "XYZ", source)
                elif key == "dof":
                    bone.dof = [p.lower() for p in parts[1:]]
                    bad = [p for p in bone.dof if p not in ("rx", "ry", "rz", "tx", "ty", "tz", "l")]
                    if bad or len(set(bone.dof)) != len(bone.dof):
                        raise ShapeMoveError(f"{source}: ASF bone {bone.name!r}: bad dof {' '.join(parts[1:])[:60]!r}")
        elif section == ":hierarchy":
            if key in ("begin", "end"):
                continue
            parent = parts[0]
            for child in parts[1:]:
                if child in listed:  # a set: checking every list would be quadratic in bones
                    raise ShapeMoveError(f"{source}: ASF hierarchy lists {child!r} twice")
                listed.add(child)
                children.setdefault(parent, []).append(child)
    if not bones:
        raise ShapeMoveError(f"{source}: ASF has no bones (not an ASF skeleton file?)")
    for parent, kids in children.items():
        for name in [parent, *kids]:
            if name != "root" and name not in bones:
                raise ShapeMoveError(f"{source}: ASF hierarchy names unknown bone {name!r}")
    for b in bones.values():
        n = np.linalg.norm(b.direction)
        if b.length and not n > 0:
            raise ShapeMoveError(f"{source}: ASF bone {b.name!r} has a zero direction")
        b.direction = b.direction / n if n > 0 else b.direction
    ang = np.pi / 180 if angle_deg else 1.0
    return Skeleton(bones, children, root_order, root_axis, root_pos, root_ori * ang, INCH / length_unit, ang,
                    str(source))


def _joint_order(skel: Skeleton):
    """DFS from the root: (names, parents, bone or None) with End Sites after leaf bones.
    Iterative; a cycle or a bone unreachable from the root is an error."""
    names, parents, owners = ["root"], [-1], [None]
    stack = [(c, 0) for c in reversed(skel.children.get("root", []))]
    seen = set()
    while stack:
        name, parent = stack.pop()
        if name in seen:
            raise ShapeMoveError(f"{skel.source}: ASF hierarchy has a cycle at {name!r}")
        seen.add(name)
        names.append(name)
        parents.append(parent)
        owners.append(name)
        idx = len(names) - 1
        kids = skel.children.get(name, [])
        if kids:
            stack.extend((c, idx) for c in reversed(kids))
        else:
            names.append(name + "_End")
            parents.append(idx)
            owners.append(None)
    if len(seen) < len(skel.bones):
        missing = sorted(set(skel.bones) - seen)[:5]
        raise ShapeMoveError(f"{skel.source}: ASF bones not connected to the root: {', '.join(missing)}")
    return names, np.array(parents, dtype=np.int64), owners


def parse_amc(text: str, skel: Skeleton, source="AMC", angle_unit: str | None = None):
    """AMC text -> (root values (T, len(root order)), {bone: (T, len(dof))}, radians per angle).
    Strict: each bone line holds exactly its ASF dof count, once per frame (else a ShapeMoveError
    naming the line). Angles in radians (``angle rad`` in the ASF or ``:RADIANS``) whose values go
    beyond +-2 pi on most frames are refused as degrees in disguise; ``angle_unit`` ('deg' or
    'rad') overrides what the files declare (and that check)."""
    return _parse_amc(iter(text.splitlines()), skel, source, angle_unit)


def _parse_amc(lines, skel: Skeleton, source, angle_unit: str | None):
    """``parse_amc`` of an iterator over the AMC's lines: values are kept as float64 as they are
    read (8 bytes a value, whatever the text's size)."""
    if angle_unit not in (None, "deg", "rad"):
        raise ShapeMoveError(f"angle unit must be 'deg' or 'rad', got {angle_unit!r}")
    angle = skel.angle_scale
    declared = "the ASF (angle rad)" if angle == 1.0 else None
    dofs = {name: len(b.dof) for name, b in skel.bones.items() if b.dof}
    dofs["root"] = len(skel.root_order)
    chunks = {name: array("d") for name in dofs}
    seen = dict.fromkeys(dofs, 0)  # frame number in which each bone was last given
    frames, frame_line, gap = 0, 0, None
    joints = 2 * len(skel.bones) + 1  # upper bound of bones + End Sites
    for line_no, raw in enumerate(lines, 1):
        line = raw.strip()
        if not line or line[0] == "#":
            continue
        if line[0] == ":":
            key = line.upper()
            if key.startswith(":RADIANS"):
                angle, declared = 1.0, f"the AMC (:RADIANS, line {line_no})"
            elif key.startswith(":DEGREES"):
                angle, declared = np.pi / 180, None
            continue
        name, rest = (line.split(None, 1) + [""])[:2]
        if name.isdigit():
            if frames and gap is None:
                gap = _frame_gap(seen, frames, frame_line, dofs, source)
            frames += 1
            frame_line = line_no
            if frames * joints > MAX_JOINT_FRAMES:  # stop before storing more lines than could ever be used
                check_joint_frames(frames, joints, source, "AMC")
            continue
        if frames == 0:
            raise ShapeMoveError(f"{source}: line {line_no}: AMC data before the first frame number: {line[:40]!r}")
        if name not in chunks:
            if name in skel.bones:  # a bone without dof listed with no values is harmless
                if rest.strip():
                    raise ShapeMoveError(f"{source}: line {line_no}: AMC gives values for {name!r}, which has no "
                                         "dof in the ASF")
                continue
            raise ShapeMoveError(f"{source}: line {line_no}: AMC names bone {name[:40]!r}, which the ASF does not define")
        toks = rest.split()
        n = len(toks)
        if n != dofs[name]:
            raise ShapeMoveError(f"{source}: line {line_no}: AMC gives {n} values for {name!r}, expected {dofs[name]} "
                                 f"per frame (its ASF dof: {' '.join(skel.bones[name].dof) if name in skel.bones else ' '.join(skel.root_order).lower()}): "
                                 "wrong skeleton or a damaged file")
        if seen[name] == frames:
            raise ShapeMoveError(f"{source}: line {line_no}: AMC gives {name!r} twice in frame {frames}")
        seen[name] = frames
        try:
            chunks[name].extend(map(float, toks))
        except ValueError:
            bad = next(t for t in toks if not is_number(t))
            raise ShapeMoveError(f"{source}: line {line_no}: AMC values for {name!r} contain something that is not a "
                                 f"number: {bad[:40]!r}") from None
    if frames == 0:
        raise ShapeMoveError(f"{source}: AMC has no frames")
    gap = gap or _frame_gap(seen, frames, frame_line, dofs, source)
    if gap is not None:  # raised after the loop: a frames x joints bomb is refused as such first
        raise ShapeMoveError(gap)
    if angle_unit is not None:
        angle, declared = (1.0 if angle_unit == "rad" else np.pi / 180), None
    values = {}
    for name in list(chunks):
        arr = np.frombuffer(chunks.pop(name), dtype=np.float64)
        if arr.size != frames * dofs[name]:  # every frame was checked to hold each bone once: cannot happen
            raise ShapeMoveError(f"{source}: AMC has {arr.size} values for {name!r}, expected {dofs[name]} per frame")
        if not np.all(np.isfinite(arr)) or (arr.size and np.abs(arr).max() > MAX_VALUE):
            raise ShapeMoveError(f"{source}: AMC values for {name!r} are NaN, inf or absurdly large")
        values[name] = arr.reshape(frames, dofs[name])
    root = values.pop("root")
    if declared is not None:
        _check_radians(skel, root, values, source, declared)
    return root, values, angle


def _frame_gap(seen: dict, frame: int, line: int, dofs: dict, source) -> str | None:
    """The error sentence when a bone with dof has no line in ``frame`` (``seen``: the frame each
    bone was last given in), else None."""
    for name in dofs:
        if seen[name] != frame:
            return (f"{source}: line {line}: AMC frame {frame} gives no lines for {name!r} (expected one line of "
                    f"{dofs[name]} values): truncated file or wrong skeleton")
    return None


RADIANS_SHARE = 0.5  # share of frames with a rotation beyond +-2 pi that makes declared radians implausible


def _check_asf_radians(skel: Skeleton, source) -> None:
    """Refuse an ASF that declares radians while most of its non-zero bone axis angles lie beyond
    +-2 pi (degrees in disguise: read as radians they turn every bone's frame by up to radians)."""
    axes = np.concatenate([np.asarray(b.axis, dtype=np.float64) for b in skel.bones.values()] or [np.zeros(0)])
    axes = np.abs(axes[axes != 0])
    if len(axes) and (axes > 2 * np.pi).mean() > RADIANS_SHARE:
        raise ShapeMoveError(f"{source}: the ASF declares angles in radians (angle rad), but {int((axes > 2 * np.pi).sum())} "
                             f"of its {len(axes)} non-zero bone axis angles go beyond +-2 pi (up to {axes.max():.1f}): "
                             "they look like degrees; pass --angle-unit deg to read them as degrees (or --angle-unit "
                             "rad to keep radians)")


def _check_radians(skel: Skeleton, root: np.ndarray, values: dict, source, declared: str) -> None:
    """Refuse rotation values declared in radians that are degrees: beyond +-2 pi on most frames."""
    cols = [root[:, i] for i, k in enumerate(skel.root_order) if k.startswith("R")]
    for name, v in values.items():
        cols += [v[:, i] for i, d in enumerate(skel.bones[name].dof) if d.startswith("r")]
    if not cols:
        return
    big = np.abs(np.stack(cols, 1))
    share = float((big > 2 * np.pi).any(1).mean())
    if share > RADIANS_SHARE:
        raise ShapeMoveError(f"{source}: {declared} declares angles in radians, but on {100 * share:.0f}% of the frames "
                             f"rotation values go beyond +-2 pi (up to {big.max():.1f}): they look like degrees; pass "
                             "--angle-unit deg to read them as degrees (or --angle-unit rad to keep radians)")


def amc_to_positions(skel: Skeleton, root: np.ndarray, values: dict, angle: float):
    """FK in file units: (names, parents, offsets (J,3), positions (T,J,3), rotations (T,J,3,3))."""
    names, parents, owners = _joint_order(skel)
    T, J = root.shape[0], len(names)
    offsets = np.zeros((J, 3))
    trans = np.zeros((T, J, 3))
    rots = np.broadcast_to(np.eye(3), (T, J, 3, 3)).copy()
    # root
    rv = {k: root[:, i] for i, k in enumerate(skel.root_order)}
    zero = np.zeros(T)
    offsets[0] = skel.root_position
    trans[:, 0] = np.stack([rv.get("TX", zero + skel.root_position[0]), rv.get("TY", zero + skel.root_position[1]),
                            rv.get("TZ", zero + skel.root_position[2])], -1)
    C = fixed_axes_matrix(skel.root_axis, skel.root_orientation)
    M = fixed_axes_matrix(skel.root_axis, np.stack([rv.get(k, zero) for k in ("RX", "RY", "RZ")], -1) * angle)
    rots[:, 0] = C @ M @ C.T
    for j in range(1, J):
        p = int(parents[j])
        parent_bone = skel.bones.get(owners[p]) if owners[p] else None
        offsets[j] = parent_bone.length * parent_bone.direction if parent_bone is not None else 0.0
        trans[:, j] = offsets[j]
        if owners[j] is None:
            continue
        b = skel.bones[owners[j]]
        if not b.dof:
            continue
        v = values[b.name]
        ang = np.zeros((T, 3))
        order = ""
        for i, d in enumerate(b.dof):
            if d[0] == "r":
                ang[:, "xyz".index(d[1])] = v[:, i] * angle
                order += d[1].upper()
        if order:
            C = fixed_axes_matrix(b.axis_order, b.axis * skel.angle_scale)
            M = fixed_axes_matrix(order, ang)
            rots[:, j] = C @ M @ C.T
    positions = forward_kinematics(rots, joints_from_offsets(trans, parents), parents)[0]
    return names, parents, offsets, positions, rots


def _read_text(path: Path, what: str) -> str:
    return read_text(path, what, MAX_HIERARCHY_BYTES if what == "ASF" else None)


def _file_lines(path: Path):
    """The decoded lines of an AMC file, one at a time (at most ``MAX_AMC_BYTES``; binary refused)."""
    with open_bounded(path, MAX_AMC_BYTES, "AMC", "split the clip") as fh:
        if b"\0" in fh.read(4096):
            raise ShapeMoveError(f"{path}: binary data, not an AMC text file")
        fh.seek(0)
        for raw in fh:
            yield raw.decode("utf-8", errors="replace")


def load_asf(path) -> Skeleton:
    path = Path(path)
    return parse_asf(_read_text(path, "ASF"), path)


def find_asf(amc_path) -> Path:
    """The ASF for an AMC: CMU ``02/02_01.amc`` -> ``02/02.asf``; HDM05 ``HDM_bd_*.amc`` ->
    ``HDM_bd.asf``; otherwise the only .asf in the folder."""
    amc_path = Path(amc_path)
    folder, stem = amc_path.parent, amc_path.stem
    parts = stem.split("_")
    candidates = [folder / f"{parts[0]}.asf"]
    if len(parts) > 1:
        candidates.append(folder / f"{parts[0]}_{parts[1]}.asf")
    for c in candidates:
        if c.is_file():
            return c
    found = sorted(folder.glob("*.asf")) + sorted(folder.glob("*.ASF"))
    if len(found) == 1:
        return found[0]
    raise ShapeMoveError(f"{amc_path}: cannot find its ASF skeleton (looked for {candidates[0].name}"
                         f"{' among ' + ', '.join(f.name for f in found) if found else ''}); pass asf=...")


def amc_fps(amc_path, default: float = 120.0) -> float:
    """HDM05 names carry the rate (``HDM_bd_kickLFront_001_120.amc``); CMU is 120 fps."""
    m = re.match(r"^HDM_.*_(\d+)$", Path(amc_path).stem)
    return float(m.group(1)) if m and 1 <= int(m.group(1)) <= 1000 else default


def load_amc(path, asf=None, fps: float | None = None, up_axis: str | None = None,
             angle_unit: str | None = None) -> Mocap:
    """Read an AMC with its ASF into a Mocap (metres, Y up). The up axis is detected for a
    humanoid we can map (CMU/HDM05 are Y up) and taken as Acclaim's Y otherwise. ``angle_unit``
    ('deg'/'rad') overrides the unit the files declare (see ``parse_amc``)."""
    path = Path(path)
    if fps is not None and not (np.isfinite(fps) and 1.0 / MAX_FRAME_TIME <= fps <= 1.0 / MIN_FRAME_TIME):
        raise ShapeMoveError(f"source frame rate {fps} must lie between {1 / MAX_FRAME_TIME:g} and "
                             f"{1 / MIN_FRAME_TIME:g} fps")
    asf_path = Path(asf) if asf else find_asf(path)
    skel = load_asf(asf_path)
    if angle_unit is not None:  # the override covers the ASF's own angles (bone axes, root orientation)
        scale = 1.0 if angle_unit == "rad" else np.pi / 180
        skel.root_orientation = skel.root_orientation * (scale / skel.angle_scale)
        skel.angle_scale = scale
    elif skel.angle_scale == 1.0:
        _check_asf_radians(skel, asf_path)
    root, values, angle = _parse_amc(_file_lines(path), skel, path, angle_unit)
    names, parents, offsets, positions, rots = amc_to_positions(skel, root, values, angle)
    subject = asf_path.stem[4:] if asf_path.stem.startswith("HDM_") else asf_path.stem
    if up_axis is None and find_rig(names) is None:
        up_axis = "Y"
    return finish_mocap(names, parents, offsets, positions, fps or amc_fps(path), str(path), rotations=rots,
                        unit=f"asf length {INCH / skel.length_scale:g}", scale=skel.length_scale,
                        up_axis=up_axis, subject=subject, meta={"asf": str(asf_path)})
