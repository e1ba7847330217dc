def tpose_lead_in(joints, fps):
    return 0
