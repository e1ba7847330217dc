"""Find the humanoid in ANY skeleton by its shape: topology (chain lengths, symmetry, end
effectors), rest-pose geometry and name hints. One engine for both directions of retargeting:
mocap import (``rig_map.detect_rig`` falls back to it for rigs absent from its tables) and the
user's own armature (``core.scene.bone_map``).

Steps (``match_humanoid``):

1. Prune: short leaf branches (fingers, toes, twist and helper bones, eyes, jaw) are removed,
   shortest first, until five ends remain: two feet, two hands, the head.
2. Classify the five ends: two pairs with equal limb lengths (symmetry) and an odd one, the head;
   the pair whose branch point lies nearer to the head are the arms. Name hints (``leg``, ``arm``,
   ``head`` ...) break ties.
3. Parse each chain: ankle = end of the leg's last descending segment, foot = the first joint
   well forward of it; hip/knee and shoulder/elbow/wrist = the joints whose segment-length ratios
   (thigh ~ shin, upper arm ~ forearm) and straightness fit best, never at the branch point;
   collar = the joint before the shoulder (placed 45% of the way out when it sits on the
   mid-line, as ``rig_map`` does for CMU clavicles); head/neck by name, else by position.
4. Left/right: names (``Left``, ``_L``, ``.l``, ``lFoot``, ``lfemur`` against ``rfemur``), else
   geometry: left = up x forward, with forward from the feet (ankle -> toe).

The result is a ``rig_map.Rig`` whose rules name the skeleton's own joints. Failures raise
``ShapeMoveError`` saying which body part could not be found and what to change.
"""
from __future__ import annotations

import heapq
import itertools
import re

import numpy as np

from ..errors import ShapeMoveError
from .rig import SPINE_JOINTS, Rig, normalize

LEG_WORDS = ("leg", "thigh", "knee", "calf", "shin", "foot", "toe", "ankle", "femur", "tibia", "hip")
ARM_WORDS = ("arm", "hand", "shoulder", "clav", "elbow", "wrist", "humerus", "radius", "shldr", "collar",
             "finger", "thumb", "index", "pinky", "palm")
END_WORDS = ("end", "top", "nub", "site", "tip")
THIGH_OVER_SHIN = 0.95    # hip->knee / knee->ankle of adults (0.8-1.05 in the archives' rigs)
UPPER_OVER_FOREARM = 1.05  # shoulder->elbow / elbow->wrist
UPPER_ARM_OVER_LEG = 0.34  # shoulder->elbow / (hip->knee->ankle) of adults
FOREARM_OVER_LEG = 0.33    # elbow->wrist / (hip->knee->ankle)
COLLAR_OUT = 0.45  # SMPL's collar joint: this fraction of the way from the mid-line to the shoulder
# words that name a role's joint (a soft preference: geometry still decides between several)
ROLE_WORDS = {"hip": ("thigh", "upleg", "upperleg", "femur"), "knee": ("shin", "calf", "knee", "lowerleg", "tibia"),
              "shoulder": ("upperarm", "upper_arm", "humerus", "shldr"),
              "elbow": ("forearm", "lowerarm", "radius", "elbow"), "wrist": ("wrist", "hand")}
HELPER_WORDS = ("twist", "roll", "helper", "end", "nub", "tip")
MAX_JOINTS = 2000  # shape matching is quadratic in the leaf count: bound the work on hostile files
MAX_CHAIN = 48     # joints from a branch point to a limb's end (a leg or arm with more is not one)


class _Tree:
    def __init__(self, names, parents, rest):
        self.names = list(names)
        self.parents = np.asarray(parents, dtype=np.int64).reshape(-1)
        self.rest = np.asarray(rest, dtype=np.float64).reshape(-1, 3)
        J = len(self.names)
        if self.parents.shape != (J,) or self.rest.shape != (J, 3):
            raise ShapeMoveError(f"skeleton arrays disagree: {J} names, {self.parents.shape} parents, "
                                 f"{self.rest.shape} rest positions")
        if not np.all(np.isfinite(self.rest)):
            raise ShapeMoveError("skeleton rest positions are not finite")
        if np.any(self.parents >= np.arange(J)) or np.any(self.parents < -1):
            raise ShapeMoveError("skeleton parents must come before their children (parents[j] < j, -1 for roots)")
        self.children = [[] for _ in range(J)]
        for j, p in enumerate(self.parents):
            if p >= 0:
                self.children[p].append(j)
        self.length = np.zeros(J)
        has = self.parents >= 0
        self.length[has] = np.linalg.norm(self.rest[has] - self.rest[self.parents[has]], axis=-1)
        self.cum = np.zeros(J)
        self.depth = np.zeros(J, dtype=np.int64)
        for j in range(J):
            p = self.parents[j]
            if p >= 0:
                self.cum[j] = self.cum[p] + self.length[j]
                self.depth[j] = self.depth[p] + 1

    def ancestors(self, j):  # j, parent, ..., root
        out = []
        while j >= 0:
            out.append(j)
            j = int(self.parents[j])
        return out

    def lca(self, a, b):
        anc = set(self.ancestors(a))
        for x in self.ancestors(b):
            if x in anc:
                return x
        return -1

    def dist(self, a, b):
        c = self.lca(a, b)
        return self.cum[a] + self.cum[b] - 2 * self.cum[c]

    def median(self, a, b, c):
        cands = [self.lca(a, b), self.lca(a, c), self.lca(b, c)]
        return max(cands, key=lambda x: self.depth[x])

    def between(self, u, v):
        """Joints on the tree path from u (excluded) to v (included)."""
        c = self.lca(u, v)
        up = self.ancestors(u)
        up = up[1:up.index(c) + 1] if u != c else []
        return up + self.down_path(c, v)

    def down_path(self, top, bottom):
        """Joints from just below ``top`` down to ``bottom`` (top must be an ancestor)."""
        out = []
        j = bottom
        while j != top and j >= 0:
            out.append(j)
            j = int(self.parents[j])
        if j != top:
            raise AssertionError("not an ancestor")
        return out[::-1]


def _words(name: str) -> str:
    for sep in (":", "|"):
        name = name.rsplit(sep, 1)[-1]
    return name


def side_hint(name: str) -> int:
    """+1 for a left-side name, -1 for right, 0 when the name does not say."""
    n = _words(name)
    low = n.lower()
    if "left" in low and "right" not in low:
        return 1
    if "right" in low and "left" not in low:
        return -1
    for sep_tok in re.split(r"[^A-Za-z0-9]+", n):
        if sep_tok.lower() in ("l", "lt"):
            return 1
        if sep_tok.lower() in ("r", "rt"):
            return -1
    if re.match(r"^l[A-Z]", n):
        return 1
    if re.match(r"^r[A-Z]", n):
        return -1
    return 0


def _pair_side(a: str, b: str) -> int:
    """+1 when names a/b differ only by l<->r at one place with a holding the l (lfemur/rfemur)."""
    a, b = _words(a).lower(), _words(b).lower()
    if len(a) != len(b):
        return 0
    diff = [i for i in range(len(a)) if a[i] != b[i]]
    if len(diff) != 1:
        return 0
    pair = a[diff[0]] + b[diff[0]]
    return 1 if pair == "lr" else -1 if pair == "rl" else 0


def _role_miss(tree, chain_part, j, role) -> float:
    """0 when ``j`` has a name of ``role`` or no joint of ``chain_part`` has one; else 1. For the
    wrist, 'wrist' names win over 'hand' names (ASF: lwrist, then lhand)."""
    words = ROLE_WORDS[role]
    for group in ((("wrist",), ("hand",)) if role == "wrist" else (words,)):
        named = [c for c in chain_part if _has_word(tree.names[c], group) and not _has_word(tree.names[c], HELPER_WORDS)]
        if named:
            return 0.0 if j in named[:1] or (role != "wrist" and j in named) else 1.0
    return 0.0


def _has_word(name, words) -> bool:
    low = _words(name).lower()
    return any(w in low for w in words)


def _is_end(tree, j) -> bool:
    """An End Site as the mocap readers name it (``<parent>_End``), or a bone tail likewise."""
    p = tree.parents[j]
    return p >= 0 and _words(tree.names[j]).lower() == _words(tree.names[p]).lower() + "_end"


def _prune(tree: _Tree, keep: int = 5):
    """Alive joints after removing the shortest leaf branches until ``keep`` ends remain (in the
    biggest tree when there are several roots). A leaf branch runs from a leaf up to the nearest
    joint with another child; lengths only grow as branches merge, so stale heap entries are
    recomputed when they surface (O(J log J) for any tree shape)."""
    J = len(tree.names)
    root_of = np.empty(J, dtype=np.int64)
    for j in range(J):
        p = tree.parents[j]
        root_of[j] = j if p < 0 else root_of[p]
    root = int(np.bincount(root_of, minlength=J).argmax())
    alive = root_of == root
    nkids = np.zeros(J, dtype=np.int64)
    for j in np.flatnonzero(alive):
        if tree.parents[j] >= 0:
            nkids[tree.parents[j]] += 1

    def branch(leaf):  # joints from the leaf up to (not including) the branch point, and the length
        path, j = [], leaf
        while j != root and nkids[tree.parents[j]] == 1:
            path.append(j)
            j = int(tree.parents[j])
        if j != root:
            path.append(j)
        return path, (tree.cum[leaf] - tree.cum[int(tree.parents[path[-1]])]) if path else 0.0

    leaves = [int(j) for j in np.flatnonzero(alive) if j != root and nkids[j] == 0]
    heap = [(branch(j)[1], j) for j in leaves]
    heapq.heapify(heap)
    count = len(leaves)
    while count > keep and heap:
        length, leaf = heapq.heappop(heap)
        if not alive[leaf]:
            continue
        path, now = branch(leaf)
        if now != length:
            heapq.heappush(heap, (now, leaf))
            continue
        if not path:
            break
        alive[path] = False
        nkids[tree.parents[path[-1]]] -= 1
        count -= 1
    leaves = [int(j) for j in np.flatnonzero(alive) if j != root and nkids[j] == 0]
    return root, alive, leaves


def _lateral(v, up):
    return v - np.dot(v, up) * up


def _too_long(tree, chain, what):
    if len(chain) > MAX_CHAIN:
        raise ShapeMoveError(f"the {what} ending at {tree.names[chain[-1]]!r} is a chain of {len(chain)} joints, "
                             f"more than {MAX_CHAIN}: not a humanoid limb (give a bone-mapping preset)")


def _leg(tree, hub, leaf, up, scale):
    chain = tree.down_path(hub, leaf)
    _too_long(tree, chain, "leg")
    P = tree.rest
    names = tree.names
    pts = [P[hub]] + [P[c] for c in chain]
    ends = []  # chain indices ending a descending segment
    for i in range(1, len(pts)):
        s = pts[i] - pts[i - 1]
        n = np.linalg.norm(s)
        if n > 0.01 * scale and -np.dot(s, up) > 0.5 * n:
            ends.append(i - 1)
    past = lambda k: max((np.linalg.norm(P[c] - P[chain[k]]) for c in chain[k + 1:]), default=0.0)  # noqa: E731
    ankle_i = ends[-1] if ends else None
    if len(ends) >= 2 and past(ends[-1]) < 0.02 * scale and past(ends[-2]) < 0.25 * scale:
        ankle_i = ends[-2]  # a frame with the heel up: the toe is the last joint going down, not the ankle
    if ankle_i is None or ankle_i < 2:
        raise ShapeMoveError(f"the leg ending at {names[leaf]!r} has no downward thigh and shin in the rest pose "
                             "(stand the skeleton upright, or use a bone-mapping preset)")
    ankle = chain[ankle_i]
    after = chain[ankle_i + 1:]
    far = max((np.linalg.norm(P[c] - P[ankle]) for c in after), default=0.0)
    foot = next((c for c in after if np.linalg.norm(P[c] - P[ankle]) >= max(0.5 * far, 0.02 * scale)), None)
    if foot is None:
        raise ShapeMoveError(f"the leg {names[chain[0]]!r} ... {names[ankle]!r} ends at the ankle: there is no toe "
                             "joint or foot end to place the SMPL foot (ball of the foot) on; add a toe bone or an "
                             "End Site to the foot")
    best = None
    span = tree.dist(hub, ankle)
    for hi, ki in itertools.combinations(range(ankle_i), 2):
        hip, knee = chain[hi], chain[ki]
        a, b = P[knee] - P[hip], P[ankle] - P[knee]
        la, lb = np.linalg.norm(a), np.linalg.norm(b)
        if la < 0.05 * scale or lb < 0.05 * scale:
            continue
        if hi + 1 < ki and np.linalg.norm(P[chain[hi + 1]] - P[hip]) < 0.1 * la:
            continue  # a tiny bone follows: the hip joint is the next one (Daz lButtock -> lThigh)
        cost = abs(np.log(la / lb / THIGH_OVER_SHIN)) + (1 - np.dot(a, b) / (la * lb))
        cost += _role_miss(tree, chain[:ankle_i], hip, "hip") + _role_miss(tree, chain[:ankle_i], knee, "knee")
        cost += 2.0 * (1 - (la + lb) / span)  # thigh + shin make most of the leg (not two halves of a shin)
        cost += 1.0 if np.linalg.norm(P[hip] - P[hub]) < 0.03 * scale else 0.0
        if best is None or cost < best[0]:
            best = (cost, hip, knee)
    if best is None:
        raise ShapeMoveError(f"the leg above {names[ankle]!r} has no separate hip and knee joints "
                             "(a humanoid leg needs thigh and shin bones)")
    return dict(hip=best[1], knee=best[2], ankle=ankle, foot=foot)


def _arm(tree, hub, leaf, up, scale, leg3):
    chain = tree.down_path(hub, leaf)
    _too_long(tree, chain, "arm")
    P = tree.rest
    names = tree.names
    best = None
    span = tree.dist(hub, leaf)
    for si, ei, wi in itertools.combinations(range(len(chain)), 3):
        s, e, w = chain[si], chain[ei], chain[wi]
        a, b = P[e] - P[s], P[w] - P[e]
        la, lb = np.linalg.norm(a), np.linalg.norm(b)
        if la < 0.05 * scale or lb < 0.05 * scale:
            continue
        hand = max(np.linalg.norm(P[c] - P[w]) for c in chain[wi:])
        cost = abs(np.log(la / lb / UPPER_OVER_FOREARM)) + (1 - np.dot(a, b) / (la * lb))
        cost += 1.0 - (la + lb) / span  # upper arm + forearm make most of the arm (not two halves of one)
        cost += abs(np.log(la / leg3 / UPPER_ARM_OVER_LEG)) + abs(np.log(lb / leg3 / FOREARM_OVER_LEG))
        cost += 0.5 * max(0.0, hand / lb - 1.0)  # a hand longer than the forearm: wrist too early
        cost += sum(_role_miss(tree, chain, j, r) for j, r in ((s, "shoulder"), (e, "elbow"), (w, "wrist")))
        cost -= 0.3 if len(tree.children[w]) >= 2 else 0.0  # fingers branch at the hand
        cost += 0.3 if si == 0 else 0.0  # humanoid rigs have a clavicle before the shoulder
        cost += 1.0 if np.linalg.norm(_lateral(P[s] - P[hub], up)) < 0.03 * scale else 0.0
        if best is None or cost < best[0]:
            best = (cost, si, ei, wi)
    if best is None:
        raise ShapeMoveError(f"the arm ending at {names[leaf]!r} has no separate shoulder, elbow and wrist "
                             "joints (a humanoid arm needs upper-arm and forearm bones)")
    _, si, ei, wi = best
    shoulder = chain[si]
    inner = chain[si - 1] if si > 0 else hub
    side = _lateral(P[shoulder] - P[hub], up)
    out_s = float(np.dot(side, side))
    f = float(np.dot(_lateral(P[inner] - P[hub], up), side)) / out_s if out_s > 0 else 0.0
    collar = names[inner] if f >= 0.3 else ("lerp", names[inner], names[shoulder],
                                              float(np.clip((COLLAR_OUT - f) / max(1 - f, 1e-6), 0, 0.9)))
    return dict(collar=collar, shoulder=shoulder, elbow=chain[ei], wrist=chain[wi])


def _head_neck(tree, spine_path, head_path, scale):
    """head and neck joint indices, and the spine chain (pelvis hub ... before the neck)."""
    names = tree.names
    named = [j for j in head_path if _has_word(names[j], ("head",)) and not _has_word(names[j], END_WORDS)]
    if named:
        head = named[-1]
    elif any(len(tree.children[j]) >= 2 for j in head_path[:-1]):
        head = [j for j in head_path[:-1] if len(tree.children[j]) >= 2][-1]  # eyes, jaw and top fork there
    elif _is_end(tree, head_path[-1]) and len(head_path) >= 2:
        head = head_path[-2]  # a reader's End Site (``<joint>_End``) or an armature's bone tail
    else:  # by shape: drop tiny end sites; a long last segment is the skull (joint -> top of head)
        path = list(head_path)
        while len(path) > 1 and tree.length[path[-1]] < 0.03 * scale:
            path.pop()
        head = path[-2] if len(path) >= 2 and tree.length[path[-1]] >= 0.12 * scale else path[-1]
    full = spine_path + head_path[:head_path.index(head) + 1]
    hi = full.index(head)
    before = full[:hi]
    necks = [k for k, j in enumerate(before) if _has_word(names[j], ("neck",))]
    ni = necks[-1] if necks else hi - 1
    if ni < 0:
        raise ShapeMoveError(f"the head {names[head]!r} sits right on the hips: no spine or neck to map")
    return head, full[ni], full[:ni]


def match_humanoid(names, parents, rest, rig_name: str = "auto"):
    """A ``rig_map.Rig`` for a humanoid skeleton of any naming: names (J,), parents (J,) with
    parents[j] < j, rest (J,3) joint positions in the rest pose (any unit, any up axis), or
    (K,J,3) candidate poses tried in turn (a rig whose rest pose lies on its back, like Bandai's
    offsets, still stands in its first frame); the first pose that matches wins."""
    poses = np.asarray(rest, dtype=np.float64)
    if poses.ndim != 3:
        return _match_pose(names, parents, poses, rig_name)
    first = None
    for pose in poses:
        try:
            return _match_pose(names, parents, pose, rig_name)
        except ShapeMoveError as exc:
            first = first or exc
    raise first if first else ShapeMoveError("no pose given to match the skeleton on")


def _match_pose(names, parents, rest, rig_name):
    if len(names) > MAX_JOINTS:
        raise ShapeMoveError(f"the skeleton has {len(names)} joints, more than the {MAX_JOINTS} a shape match "
                             "looks at: give a bone-mapping preset")
    tree = _Tree(names, parents, rest)
    norm = [normalize(n) for n in tree.names]
    extent = float(np.ptp(tree.rest, axis=0).max()) if len(tree.names) else 0.0
    if not extent > 0:
        raise ShapeMoveError("the skeleton's rest pose has zero size: cannot find its limbs")
    root, alive, leaves = _prune(tree)
    if len(leaves) < 5:
        raise ShapeMoveError(
            f"cannot find a humanoid: the skeleton has {len(leaves)} limb end(s) "
            f"({', '.join(tree.names[j] for j in leaves) or 'none'}); a humanoid needs five ends, two feet, two "
            "hands and a head (a whole-body skeleton, or a bone-mapping preset)")

    best = None
    for h in leaves:
        rest4 = [x for x in leaves if x != h]
        for a in rest4[1:]:
            A = (rest4[0], a)
            B = tuple(x for x in rest4 if x not in A)
            for arms, legs in ((A, B), (B, A)):
                ha, hl = tree.median(*arms, h), tree.median(*legs, h)
                la = [tree.dist(ha, x) for x in arms]
                ll = [tree.dist(hl, x) for x in legs]
                if min(la + ll) <= 0:
                    continue
                cost = abs(np.log(la[0] / la[1])) + abs(np.log(ll[0] / ll[1]))
                cost += 1.0 if tree.dist(h, ha) > tree.dist(h, hl) else 0.0  # the head sits by the arms
                # the arms' hub lies between the legs' hub and the head
                cost += 1.0 if abs(tree.dist(hl, ha) + tree.dist(ha, h) - tree.dist(hl, h)) > 1e-9 * extent else 0.0
                hint = 0
                for x in arms:
                    path = tree.between(ha, x)
                    hint += any(_has_word(tree.names[j], ARM_WORDS) for j in path)
                    hint -= any(_has_word(tree.names[j], ("leg", "thigh", "foot", "toe", "femur")) for j in path)
                for x in legs:
                    path = tree.between(hl, x)
                    hint += any(_has_word(tree.names[j], LEG_WORDS) for j in path)
                    hint -= any(_has_word(tree.names[j], ("arm", "hand", "clav", "finger")) for j in path)
                hint += any(_has_word(tree.names[j], ("head",)) for j in tree.between(ha, h))
                cost -= 0.1 * hint
                if best is None or cost < best[0]:
                    best = (cost, h, arms, legs, ha, hl)
    _, head_leaf, arms, legs, hub_a, hub_l = best
    leg_len = np.mean([tree.dist(hub_l, x) for x in legs])
    for label, pair, hub in (("arms", arms, hub_a), ("legs", legs, hub_l)):
        la, lb = (tree.dist(hub, x) for x in pair)
        if max(la, lb) > 1.25 * min(la, lb):
            raise ShapeMoveError(
                f"cannot find a humanoid: the best pair of {label} ({tree.names[pair[0]]}, {tree.names[pair[1]]}) "
                f"differ in length by {abs(la - lb) / min(la, lb):.0%}; a humanoid needs five ends, two feet, two "
                "hands and a head, with matching left and right limbs (a whole-body skeleton, or a bone-mapping "
                "preset)")
    for label, ends, hub in (("arm", arms, hub_a), ("leg", legs, hub_l)):
        short = [x for x in ends if tree.dist(hub, x) < 0.4 * leg_len]
        if short:
            raise ShapeMoveError(
                f"cannot find a humanoid: its longest limb ends are {', '.join(tree.names[j] for j in leaves)}, "
                f"and the best fit would make {tree.names[short[0]]!r} an {label} "
                f"{tree.dist(hub, short[0]) / leg_len:.0%} as long as the legs; a humanoid needs five ends, two "
                "feet, two hands and a head (a whole-body skeleton, or a bone-mapping preset)")
    if any(tree.lca(hub_a, x) != hub_a for x in (*arms, head_leaf)) \
            or any(tree.lca(hub_l, x) != hub_l for x in legs):
        raise ShapeMoveError(f"cannot find a humanoid: the arms ({tree.names[arms[0]]}, {tree.names[arms[1]]}) do "
                             f"not hang from a spine above the legs ({tree.names[legs[0]]}, {tree.names[legs[1]]})")
    up = tree.rest[hub_a] - tree.rest[hub_l]
    if np.linalg.norm(up) < 1e-3 * extent:
        up = tree.rest[head_leaf] - tree.rest[hub_l]
    up = up / max(np.linalg.norm(up), 1e-12)
    leg_parts = [_leg(tree, hub_l, x, up, leg_len) for x in legs]
    leg3 = np.mean([np.linalg.norm(tree.rest[p["knee"]] - tree.rest[p["hip"]])
                    + np.linalg.norm(tree.rest[p["ankle"]] - tree.rest[p["knee"]]) for p in leg_parts])
    arm_parts = [_arm(tree, hub_a, x, up, leg_len, leg3) for x in arms]

    # left/right: names first, then geometry (left = up x forward, forward from the feet)
    def name_vote(pa, pb, ja, jb):
        v = sum(side_hint(tree.names[j]) for j in ja) - sum(side_hint(tree.names[j]) for j in jb)
        v += sum(_pair_side(tree.names[x], tree.names[y]) for x, y in zip(ja, jb))
        return v

    fwd = sum(_lateral(tree.rest[p["foot"]] - tree.rest[p["ankle"]], up) for p in leg_parts)
    fwd_ok = np.linalg.norm(fwd) > 0.02 * leg_len
    left_axis = np.cross(up, fwd / max(np.linalg.norm(fwd), 1e-12))

    def order(parts, ends, hub, key):
        ja, jb = (tree.down_path(hub, e) for e in ends)
        v = name_vote(*parts, ja, jb)
        if v == 0:
            if not fwd_ok:
                raise ShapeMoveError("cannot tell the left limbs from the right: no Left/Right (L/R) in the joint "
                                     "names and no toes to tell forward from; rename the joints or use a preset")
            v = np.dot(tree.rest[parts[0][key]] - tree.rest[parts[1][key]], left_axis)
        return parts if v > 0 else parts[::-1]

    leg_l, leg_r = order(leg_parts, legs, hub_l, "hip")
    arm_l, arm_r = order(arm_parts, arms, hub_a, "shoulder")
    base = tree.lca(hub_l, hub_a)  # where the legs' branch meets the spine (the legs' hub, or above it)
    spine_path = [base] + tree.down_path(base, hub_a) if hub_a != base else [base]
    mid_hips = 0.5 * (tree.rest[leg_l["hip"]] + tree.rest[leg_r["hip"]])
    if len(spine_path) > 1 and np.dot(tree.rest[base] - mid_hips, up) < -0.01 * leg3:
        spine_path = spine_path[1:]  # a root below the hip joints (Daz's `hip`) is not on the spine
    head, neck, spine = _head_neck(tree, spine_path, tree.down_path(hub_a, head_leaf), leg_len)

    if len(set(norm)) != len(norm):
        dup = sorted({n for n in norm if norm.count(n) > 1})
        raise ShapeMoveError(f"joint names repeat ({', '.join(dup[:5])}): rename them so each is unique")
    N = tree.names
    rules = {}
    for side, leg, arm in (("left", leg_l, arm_l), ("right", leg_r, arm_r)):
        for k in ("hip", "knee", "ankle", "foot"):
            rules[f"{side}_{k}"] = N[leg[k]]
        rules[f"{side}_collar"] = arm["collar"]
        for k in ("shoulder", "elbow", "wrist"):
            rules[f"{side}_{k}"] = N[arm[k]]
    rules["neck"], rules["head"] = N[neck], N[head]
    for k, joint in enumerate(SPINE_JOINTS):
        rules[joint] = ("chain", k)
    return Rig(rig_name, rules, tuple(N[j] for j in spine) + (N[neck],), N[neck], N[head])
