"""IK benchmark: ``solve_ik`` (analytic + short batched refinement) against an SMPLify-style
LBFGS optimisation from identity rotations (100 iterations), on the same frames.

Targets: real clips (Bandai, HDM05, CMU through ``core.io.mocap.load_smpl22``, 20 fps) retargeted
onto the body model fitted to each clip's bone lengths; without the archives, FK of random
plausible poses on the body. Times are the best of a few repeats (the machine is shared).
"""
from __future__ import annotations

import time

import numpy as np
import torch

CLIPS = [  # (archive folder, glob) - the first match of each
    ("bandai", "dataset-1/data/dataset-1_walk-back_active_001.bvh"),
    ("bandai", "dataset-1/data/dataset-1_dash_active_001.bvh"),
    ("bandai", "dataset-2/data/*_raise-up-both-hands_*.bvh"),
    ("hdm05", "**/*.amc"),
    ("cmu", "bvh/**/*.bvh"),
    ("bandai", "dataset-1/data/dataset-1_bow_active_001.bvh"),
]


def _body_rest():
    """The default body model (OpenBody) and its mean rest joints (24,3)."""
    from ..core.body.load import load_body_model

    body = load_body_model()
    return body, body.rest_joints()[0].double().numpy()


def _fit_rest(body, rest, joints):
    """Rest joints of the body fitted to the clip's bone lengths; the fit's bone-length RMS (m)."""
    from ..core.body.skeleton import PARENTS

    lengths = np.median(np.linalg.norm(joints[:, 1:] - joints[:, PARENTS[1:22]], axis=-1), 0)
    try:
        from ..core.body.fit import fit_betas_to_bone_lengths

        fit = fit_betas_to_bone_lengths(body, lengths)
        return body.rest_joints(torch.tensor(fit.betas)[None])[0].double().numpy(), fit.residual
    except ImportError:
        from ..core.body.ik import rest_with_bone_lengths

        return rest_with_bone_lengths(rest, lengths), 0.0


def _real_clips(n: int, max_frames: int):
    from ..core.io.archive import mocap_root
    from ..core.io.mocap import load_smpl22

    root = mocap_root()
    out = []
    for folder, pattern in CLIPS:
        paths = sorted((root / folder).glob(pattern))
        if not paths:
            continue
        m = load_smpl22(paths[0])
        out.append((f"{folder}/{paths[0].name}", m.joints[:max_frames]))
        if len(out) == n:
            break
    return out


def _synthetic_clip(rest, frames: int, seed: int = 0):
    from ..core.body.kinematics import axis_angle_to_matrix, forward_kinematics
    from ..core.body.skeleton import PARENTS

    g = torch.Generator().manual_seed(seed)
    t = torch.linspace(0, 2 * np.pi, frames, dtype=torch.float64)[:, None, None]
    amp = torch.rand(1, 24, 3, generator=g, dtype=torch.float64) * 0.6
    phase = torch.rand(1, 24, 3, generator=g, dtype=torch.float64) * 6.3
    aa = amp * torch.sin(t + phase)
    aa[:, 0, 1] += t[:, 0, 0]  # turning on the spot
    pos, _ = forward_kinematics(axis_angle_to_matrix(aa), torch.tensor(rest).expand(frames, -1, -1), PARENTS)
    return [("synthetic", pos[:, :22].numpy())]


def _best_time(fn, repeats: int):
    best, out = float("inf"), None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def run(quick: bool = False) -> dict:
    from ..core.body.ik import ik_lbfgs_baseline, solve_ik
    from ..core.body.skeleton import JOINT_NAMES

    torch.set_num_threads(1)
    body, rest = _body_rest()
    max_frames = 120 if quick else 400
    try:
        clips = _real_clips(2 if quick else 5, max_frames)
    except Exception as exc:  # archives absent: synthetic targets
        print(f"  real clips unavailable ({exc}); using synthetic poses")
        clips = []
    if not clips:
        clips = _synthetic_clip(rest, max_frames)
    solve_ik(clips[0][1][:8], rest)  # warm-up (torch lazy init)

    t_ours = t_base = t_analytic = 0.0
    err_ours, err_base, err_analytic, frames = [], [], [], 0
    for name, joints in clips:
        fitted, fit_rms = _fit_rest(body, rest, joints)
        ta, ana = _best_time(lambda: solve_ik(joints, fitted, refine_iters=0), 3)
        to, ours = _best_time(lambda: solve_ik(joints, fitted), 3)
        tb, base = _best_time(lambda: ik_lbfgs_baseline(joints, fitted, iters=100), 1)
        T = len(joints)
        frames += T
        t_ours, t_base, t_analytic = t_ours + to, t_base + tb, t_analytic + ta
        err_ours.append(ours.joint_error.mean() * T)
        err_base.append(base.joint_error.mean() * T)
        err_analytic.append(ana.joint_error.mean() * T)
        print(f"  {name}: {T} frames, body fit bone RMS {fit_rms * 100:.2f} cm | solve_ik {to * 1000:.0f} ms "
              f"(analytic only {ta * 1000:.0f} ms) err {ours.mean_error_cm:.2f} cm "
              f"(analytic {ana.mean_error_cm:.2f}) | LBFGS-100 baseline {tb * 1000:.0f} ms err {base.mean_error_cm:.2f} cm")
        per = ours.per_joint_error_cm()
        worst = np.argsort(per)[::-1][:4]
        print("    worst joints (cm): " + ", ".join(f"{JOINT_NAMES[j]} {per[j]:.2f}" for j in worst))
    e_ours = float(np.sum(err_ours) / frames * 100)
    e_base = float(np.sum(err_base) / frames * 100)
    e_ana = float(np.sum(err_analytic) / frames * 100)
    speedup = t_base / t_ours
    print(f"  total {frames} frames: solve_ik {t_ours:.3f} s ({frames / t_ours:.0f} frames/s), "
          f"baseline {t_base:.3f} s -> speedup x{speedup:.1f}; error {e_ours:.3f} cm vs baseline {e_base:.3f} cm "
          f"(analytic only {e_ana:.3f} cm, x{t_base / t_analytic:.0f} faster)")
    return {"ik_speedup": speedup, "ik_err_cm": e_ours, "ik_baseline_err_cm": e_base,
            "ik_analytic_err_cm": e_ana, "ik_analytic_speedup": t_base / t_analytic, "ik_time_s": t_ours,
            "ik_baseline_time_s": t_base, "ik_frames": frames, "ik_clips": len(clips)}
