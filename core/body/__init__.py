"""Body models (OpenBody, SMPL family), kinematics, shape fitting, measurements and IK."""
