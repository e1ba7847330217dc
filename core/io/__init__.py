"""Readers for motion-capture files (BVH, ASF/AMC, AMASS .npz, HumanML3D folders) and archives."""
