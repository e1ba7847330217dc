"""Rotations and forward kinematics: numpy in ``rotations`` and ``fk`` (no torch, so the Blender
side and the mocap readers use them), torch twins with the same names in ``torch_ops`` where
gradients need them."""
