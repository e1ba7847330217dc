"""HumanML3D 263-dim motion features: joints <-> features, named slices, normalisation stats.

The names below load on first use (PEP 562), so ``core.motion.contacts`` imports without torch
(the Blender side uses it)."""
from importlib import import_module

_HOME = {**dict.fromkeys(("FEATURE_DIM", "feature_slices", "features_from_joints", "joints_from_features",
                          "local_rotations_from_joints", "mean_std", "root_from_features"), "features"),
         **dict.fromkeys(("canonicalize", "facing_directions", "floor_height"), "skeleton_ops")}

__all__ = list(_HOME)


def __getattr__(name):
    if name in _HOME:
        return getattr(import_module(f".{_HOME[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
