"""Evaluation metrics (Shape My Moves' physics and bone metrics, HUMOS's dynamic stability).

Motions are 20 fps, metres, Y up, ground at y = 0. ``evaluate_motion`` gives the per-clip dict,
``aggregate`` pools clips (frame-weighted), ``print_table`` shows them beside the ground truth.
"""
from .bones import bone_length_error_mm, bone_length_variance_mm, bone_lengths, mpjpe_mm, target_bone_lengths
from .evaluate import METRIC_KEYS, evaluate_joints, evaluate_motion, mesh_motion
from .physics import floating, lowest_heights, penetrate, skate, skate_from_joints
from .report import aggregate, format_table, print_table
from .stability import MassModel, convex_hull_2d, distance_outside, dynamic_stability, zmp

__all__ = [
    "METRIC_KEYS", "MassModel", "aggregate", "bone_length_error_mm", "bone_length_variance_mm", "bone_lengths",
    "convex_hull_2d", "distance_outside", "dynamic_stability", "evaluate_joints", "evaluate_motion",
    "floating", "format_table", "lowest_heights", "mesh_motion", "mpjpe_mm", "penetrate", "print_table",
    "skate", "skate_from_joints", "target_bone_lengths", "zmp",
]
