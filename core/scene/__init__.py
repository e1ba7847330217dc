"""Pure maths for building a Blender scene from a body and a motion (never imports bpy).

axes: Y-up -> Z-up; bones: bone head/tail/roll and Blender's bone rest matrices; pose: local joint
rotations -> pose-bone quaternions; shape_keys: shape-key coordinates; rig_data: everything a
scene needs from a BodyModel in Blender axes; motion_file: the motion ``.npz`` format;
capsule_body: a small procedural BodyModel for tests and benchmarks; bodies: body model by id.
"""
