"""The paper's penetrate/float (mean over ALL frames of the lowest point's depth/height, no
tolerance) beside ours (mean over the frames beyond 5 mm), on synthetic heights and a posed mesh."""
import numpy as np
import pytest
import torch

from shapemove.core.eval import physics
from shapemove.core.eval.evaluate import METRIC_KEYS, evaluate_motion


def test_paper_definitions_average_over_all_frames():
    low = np.array([-0.01, -0.01, 0.02, 0.0, 0.003, -0.002])
    assert physics.penetrate_all(low) == (pytest.approx((1 + 1 + 0.2) / 6), 6)
    assert physics.floating_all(low) == (pytest.approx((2 + 0.3) / 6), 6)
    assert physics.penetrate(low).value == pytest.approx(1.0)      # ours: the 2 frames deeper than 5 mm
    assert physics.floating(low).value == pytest.approx(2.0)


def test_evaluate_motion_reports_both(openbody):
    T = 12
    rot = np.broadcast_to(np.eye(3), (T, 24, 3, 3)).copy()
    with torch.no_grad():
        ground = -float(openbody(None).vertices[0, :, 1].min())      # rest pose's lowest vertex on y = 0
    transl = np.zeros((T, 3))
    transl[:, 1] = ground + np.where(np.arange(T) < 6, -0.01, 0.03)  # 6 frames 1 cm under, 6 frames 3 cm over
    r = evaluate_motion(openbody, None, rot, transl)
    assert {"penetrate_all_cm", "float_all_cm", "skate_joints_pct"} <= set(METRIC_KEYS) <= set(r)
    assert r["penetrate_all_cm"] == pytest.approx(0.5, abs=1e-3) and r["penetrate_cm"] == pytest.approx(1.0, abs=1e-3)
    assert r["float_all_cm"] == pytest.approx(1.5, abs=1e-3) and r["float_cm"] == pytest.approx(3.0, abs=1e-3)
    assert r["skate_joints_pct"] == 0.0
