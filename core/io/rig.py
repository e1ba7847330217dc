"""What a skeleton mapping is (``Rig``: how one family of skeletons maps to SMPL22), the SMPL
spine joints it places along the rig's spine chain, and how source joint names are compared
(``normalize``). A leaf of ``core.io``: the rig tables (``rig_map``) and the shape matcher
(``skeleton_match``) both build ``Rig``s.
"""
from __future__ import annotations

from dataclasses import dataclass

SPINE_JOINTS = ("pelvis", "spine1", "spine2", "spine3")


@dataclass(frozen=True)
class Rig:
    """How one family of skeletons maps to SMPL22. ``chain``: spine points from the hips upward
    (the mid-hips point is prepended automatically; names in ``optional`` may be missing)."""

    name: str
    rules: dict
    chain: tuple
    neck: str
    head: str
    optional: tuple = ()


def normalize(name: str) -> str:
    """Case-folded joint name without a namespace prefix (``mixamorig:LeftArm`` -> ``leftarm``)."""
    for sep in (":", "|"):
        name = name.rsplit(sep, 1)[-1]
    return name.strip().lower()
