"""What a ShapeMove rig holds, read from its custom properties and its body's shape keys: the rig
of an object, its body mesh, its current and placed betas, the worker's body spec for it.

A leaf of the add-on (no other add-on module imports back), so shape syncing, re-decoding, the
panels and the operators all read rigs the same way.
"""
from __future__ import annotations

import bpy
import numpy as np

from ..core.constants import NUM_BETAS, is_openbody
from .preferences import body_spec
from .scene_build import RIG_MARK


PHYSICS_KEY = "shapemove_physics"  # a generated motion's physics figures (the generate job's, stored by the operator)
PROVENANCE_KEY = "shapemove_provenance"  # where the motion came from: "generated", "captured: HDM05 bd kickLFront 003 (...)"
TAKE_NOTES_KEY = "shapemove_take_notes"  # a take played from its own rotations, and why (retarget, a library clip)


def rig_of(obj):
    """The ShapeMove armature for ``obj`` (the armature itself or its body mesh), or None."""
    for cand in (obj, getattr(obj, "parent", None)):
        if cand is not None and cand.type == "ARMATURE" and cand.get(RIG_MARK):
            return cand
    return None


def body_of(rig):
    body = rig.get("shapemove_body")
    return body if isinstance(body, bpy.types.Object) and body.type == "MESH" else None


def current_betas(rig) -> np.ndarray:
    """(10,) the body's shape-key values (zeros for missing keys)."""
    body = body_of(rig)
    keys = body.data.shape_keys.key_blocks if body and body.data.shape_keys else {}
    return np.array([keys[f"beta_{i}"].value if f"beta_{i}" in keys else 0.0 for i in range(NUM_BETAS)])


def placed_betas(rig) -> np.ndarray:
    """(10,) the betas the bones were last placed for."""
    return np.array(rig.get("shapemove_betas", [0.0] * NUM_BETAS), dtype=np.float64)  # a copy, not a view of the ID property


def rig_body_spec(rig) -> str:
    """The worker's "body" for a rig: openbody, or the SMPL file of the preferences."""
    return "openbody" if rig is None or is_openbody(rig.get("shapemove_body_model", "")) else body_spec()
