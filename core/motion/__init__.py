"""HumanML3D 263-dim motion features: joints <-> features, named slices, normalisation stats."""
from .features import (FEATURE_DIM, feature_slices, features_from_joints, joints_from_features,
                       local_rotations_from_joints, mean_std, root_from_features)
from .skeleton_ops import canonicalize, facing_directions, floor_height

__all__ = ["FEATURE_DIM", "feature_slices", "features_from_joints", "joints_from_features",
           "local_rotations_from_joints", "mean_std", "root_from_features", "canonicalize",
           "facing_directions", "floor_height"]
