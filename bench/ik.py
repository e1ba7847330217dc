"""IK benchmark: ``solve_ik`` (analytic + short batched refinement) against an SMPLify-style
LBFGS optimisation from identity rotations (100 iterations), on the same frames.

Targets: real clips (Bandai, HDM05, CMU through ``core.io.mocap.load_smpl22``, 20 fps) retargeted
onto the body model fitted to each clip's bone lengths; without the archives, FK of random
plausible poses on the body. Times are the best of a few repeats (the machine is shared).

Then, per archive (5 clips each), the joint error of the real pipeline (rig map -> betas -> IK on
OpenBody) for each rig-map layout and body fit: the legacy SMPL spine fractions with the
exact-skeleton bone-length fit (the baseline), OpenBody's layout (``core.io.rig_map``), and the
plausible-body fits ``fit_betas_to_motion`` and ``fit_betas_to_clip`` (the data builder's; also
with its 10 IK steps, with and without the calibrated torso/girdle offsets of ``joint_offsets``:
the builder's marker error, its joint-centre error and the offsets' sizes) (largest |beta| printed: the exact-skeleton fit reaches its cm by betas of
+-20..60, i.e. deformed bodies).
"""
from __future__ import annotations

import time

import numpy as np
import torch

from ..core.body.fit import bone_lengths, fit_betas_to_bone_lengths, fit_betas_to_clip, fit_betas_to_motion
from ..core.body.ik import bone_turn_deg, ik_lbfgs_baseline, solve_ik
from ..core.body.joint_offsets import CALIBRATED_JOINTS, solve_ik_calibrated
from ..core.body.load import load_body_model
from ..core.body.skeleton import JOINT_NAMES, PARENTS
from ..core.geometry.torch_ops import axis_angle_to_matrix, forward_kinematics
from ..core.io.archive import mocap_root
from ..core.io.mocap import load_mocap, load_smpl22
from ..core.io.resample import resample_positions
from ..core.io.rig_map import DEFAULT_LAYOUT, OPENBODY_LAYOUT, SMPL_LAYOUT, detect_rig, mapping_matrix

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
    body = load_body_model()
    return body, body.rest_joints()[0].double().numpy()


def _fit_rest(body, joints):
    """Rest joints (24,3) of the body with betas fitted to the clip's bone lengths, and the fit's
    bone-length RMS (m)."""
    lengths = np.median(np.linalg.norm(joints[:, 1:] - joints[:, PARENTS[1:22]], axis=-1), 0)
    fit = fit_betas_to_bone_lengths(body, lengths)
    return body.rest_joints(torch.tensor(fit.betas)[None])[0].double().numpy(), fit.residual


def _real_clips(n: int, max_frames: int):
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


SHOULDERS = [JOINT_NAMES.index("left_shoulder"), JOINT_NAMES.index("right_shoulder")]
ARCHIVE_CLIPS = {  # archive -> globs (the first match of each), 5 clips per archive
    "bandai": ["dataset-1/data/dataset-1_walk-back_active_001.bvh", "dataset-1/data/dataset-1_dash_active_001.bvh",
               "dataset-1/data/dataset-1_bow_active_001.bvh", "dataset-2/data/*_raise-up-both-hands_*.bvh",
               "dataset-1/data/dataset-1_kick_*.bvh"],
    "hdm05": ["mm/HDM_mm_grabHighR_*.amc", "bk/*jogLeftCircle*.amc", "dg/*hopBoth*.amc", "bd/*kickLFront*.amc",
              "mm/*squat*.amc"],
    "cmu": ["bvh/02/*.bvh", "bvh/07/*.bvh", "bvh/13/*.bvh", "bvh/09/*.bvh", "asfamc/03/03_01.amc"],
}


def _archive_table(body, quick: bool) -> dict:
    """Mean joint error (cm) per archive and (layout, fit); per joint for the baseline and the best."""
    layouts = {"smpl": SMPL_LAYOUT, "default": DEFAULT_LAYOUT, "openbody": OPENBODY_LAYOUT}
    fits = {"lengths": lambda j: fit_betas_to_bone_lengths(body, np.median(bone_lengths(j), 0)),
            "motion": lambda j: fit_betas_to_motion(body, j),
            "clip": lambda j: fit_betas_to_clip(body, j)}
    root, frames, out = mocap_root(), 60 if quick else 200, {}
    for archive, patterns in ARCHIVE_CLIPS.items():
        err, per, beta, calib = {}, {}, {}, {}
        for pattern in patterns[:1 if quick else None]:
            paths = sorted((root / archive).glob(pattern))
            if not paths:
                continue
            mocap = load_mocap(paths[0])
            rig = detect_rig(mocap.names)
            for lname, layout in layouts.items():
                W = mapping_matrix(rig, mocap.names, mocap.positions, layout)
                joints = resample_positions(np.matmul(W, mocap.positions), mocap.fps, 20.0)[:frames]
                for fname, fit_fn in fits.items():
                    fit = fit_fn(joints)
                    rest = body.rest_joints(torch.tensor(fit.betas)[None])[0].double().numpy()
                    res = solve_ik(joints, rest)
                    err.setdefault((lname, fname), []).append(res.mean_error_cm)
                    if lname == "openbody" and fname == "clip":  # the data builder's settings
                        err.setdefault(("openbody", "clip+10"), []).append(
                            solve_ik(joints, rest, refine_iters=10).mean_error_cm)
                        cal = solve_ik_calibrated(joints, rest, refine_iters=10)  # what the builder runs
                        err.setdefault(("openbody", "clip+10+cal"), []).append(cal.marker_error_cm)
                        calib.setdefault("raw", []).append(cal.raw_error_cm)
                        calib.setdefault("offsets", []).append(cal.offset_cm[list(CALIBRATED_JOINTS)])
                        calib.setdefault("shoulder_x", []).append(cal.offsets[SHOULDERS, 0] * 100.0)
                    per.setdefault((lname, fname), []).append(res.per_joint_error_cm())
                    beta[(lname, fname)] = max(beta.get((lname, fname), 0.0), float(np.abs(fit.betas).max()))
        if not err:
            continue
        n = len(err[("smpl", "lengths")])
        print(f"  {archive} ({n} clips, <= {frames} frames): mean joint error cm (max |beta|)")
        for (lname, fname), e in err.items():
            b = beta[(lname, fname.split("+")[0])]
            note = {"clip+10": " (10 IK steps, joint centres)",
                    "clip+10+cal": " (the data builder's: 10 IK steps, calibrated torso/girdle joints; marker error)"
                    }.get(fname, "")
            print(f"    layout {lname:8s} fit {fname:7s}: {np.mean(e):5.2f} cm  ({b:.1f}){note}")
        for key in (("smpl", "lengths"), ("openbody", "clip")):
            pj = np.mean(per[key], 0)
            print(f"    per joint, {key[0]} + {key[1]}: " + ", ".join(f"{JOINT_NAMES[j]} {pj[j]:.1f}" for j in range(22)))
        before, after = np.mean(err[("smpl", "lengths")]), np.mean(err[("openbody", "clip")])
        print(f"    -> {before:.2f} cm (legacy layout, exact-skeleton fit) vs {after:.2f} cm (OpenBody layout, "
              f"plausible fit): ratio {before / after:.2f}")
        out[f"ik_{archive}_legacy_err_cm"] = float(before)
        out[f"ik_{archive}_err_cm"] = float(after)
        out[f"ik_{archive}_motion_fit_err_cm"] = float(np.mean(err[("openbody", "motion")]))
        out[f"ik_{archive}_builder_uncalibrated_err_cm"] = float(np.mean(err[("openbody", "clip+10")]))
        offs = np.concatenate(calib["offsets"])
        out[f"ik_{archive}_builder_err_cm"] = float(np.mean(err[("openbody", "clip+10+cal")]))
        out[f"ik_{archive}_builder_raw_err_cm"] = float(np.mean(calib["raw"]))
        out[f"ik_{archive}_offset_mean_cm"], out[f"ik_{archive}_offset_max_cm"] = float(offs.mean()), float(offs.max())
        print(f"    builder (calibrated): marker error {out[f'ik_{archive}_builder_err_cm']:.2f} cm, joint-centre error "
              f"{out[f'ik_{archive}_builder_raw_err_cm']:.2f} cm (uncalibrated "
              f"{out[f'ik_{archive}_builder_uncalibrated_err_cm']:.2f}); offsets of the {len(CALIBRATED_JOINTS)} "
              f"calibrated joints mean {offs.mean():.1f} cm, max {offs.max():.1f} cm")
        # where the rig puts a shoulder, sideways along the collar bone from OpenBody's (+: further out on
        # the left, in on the right): archives that disagree in sign cannot share one body placement
        sx = np.mean(calib["shoulder_x"], 0)
        out[f"ik_{archive}_left_shoulder_offset_x_cm"] = float(sx[0])
        out[f"ik_{archive}_right_shoulder_offset_x_cm"] = float(sx[1])
        print(f"    mean shoulder offset along the collar (x, left/right): {sx[0]:+.1f} / {sx[1]:+.1f} cm")
        out[f"ik_{archive}_default_layout_err_cm"] = float(np.mean(err[("default", "motion")]))
        out[f"ik_{archive}_openbody_lengths_fit_err_cm"] = float(np.mean(err[("openbody", "lengths")]))
        out[f"ik_{archive}_max_abs_beta"] = beta[("openbody", "clip")]
        out[f"ik_{archive}_legacy_max_abs_beta"] = beta[("smpl", "lengths")]
    return out


def smooth_rotations(frames: int, seed: int = 0, amplitude: float = 0.6) -> torch.Tensor:
    """(frames, 24, 3) float64 axis-angles: every joint swings sinusoidally (random amplitude up to
    ``amplitude`` rad and phase, seeded) while the root turns once on the spot; a synthetic clip."""
    g = torch.Generator().manual_seed(seed)
    t = torch.linspace(0, 2 * np.pi, frames, dtype=torch.float64)[:, None, None]
    amp = torch.rand(1, 24, 3, generator=g, dtype=torch.float64) * amplitude
    phase = torch.rand(1, 24, 3, generator=g, dtype=torch.float64) * 6.3
    aa = amp * torch.sin(t + phase)
    aa[:, 0, 1] += t[:, 0, 0]  # turning on the spot
    return aa


def _synthetic_clip(rest, frames: int, seed: int = 0):
    aa = smooth_rotations(frames, seed)
    pos, _ = forward_kinematics(axis_angle_to_matrix(aa), torch.tensor(rest).expand(frames, -1, -1), PARENTS)
    return [("synthetic", pos[:, :22].numpy())]


def _best_time(fn, repeats: int):
    best, out = float("inf"), None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _reachable(res, rest):
    """FK of an IK result: targets the body reaches exactly (a real motion on a body that fits)."""
    rot = torch.tensor(res.rotations, dtype=torch.float64)
    pos, _ = forward_kinematics(rot, torch.tensor(rest).expand(len(rot), -1, -1), PARENTS)
    return pos[:, :22].numpy() + res.transl[:, None]


class _Tally:
    """Time, frame-weighted joint error and bone turns of one method over the clips."""

    def __init__(self):
        self.time, self.err, self.frames, self.turns = 0.0, 0.0, 0, []

    def add(self, seconds, res, rest, joints):
        self.time += seconds
        self.err += float(res.joint_error.mean()) * len(joints)
        self.frames += len(joints)
        self.turns.append(bone_turn_deg(res.rotations, res.transl, rest, joints).ravel())
        return res

    @property
    def err_cm(self) -> float:
        return self.err / max(self.frames, 1) * 100

    @property
    def turn_p99(self) -> float:
        return float(np.percentile(np.concatenate(self.turns), 99))


def run(quick: bool = False) -> dict:
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
    solve_ik(clips[0][1][:8], rest)  # warm-up
    ik_lbfgs_baseline(clips[0][1][:8], rest, iters=2)

    ours, analytic, loose, base, ours_fit, base_fit, ours10 = (_Tally() for _ in range(7))
    for name, joints in clips:
        fitted, fit_rms = _fit_rest(body, joints)
        r = ours.add(*_best_time(lambda: solve_ik(joints, fitted), 3), fitted, joints)
        ours10.add(*_best_time(lambda: solve_ik(joints, fitted, refine_iters=10), 3), fitted, joints)
        a = analytic.add(*_best_time(lambda: solve_ik(joints, fitted, refine_iters=0), 3), fitted, joints)
        lo = loose.add(*_best_time(lambda: solve_ik(joints, fitted, max_turn_deg=89), 1), fitted, joints)
        b = base.add(*_best_time(lambda: ik_lbfgs_baseline(joints, fitted, iters=100), 1), fitted, joints)
        # the same motion on a body that fits it exactly: IK accuracy without the body-fit error
        exact = _reachable(r, fitted)
        rf = ours_fit.add(*_best_time(lambda: solve_ik(exact, fitted), 1), fitted, exact)
        bf = base_fit.add(*_best_time(lambda: ik_lbfgs_baseline(exact, fitted, iters=100), 1), fitted, exact)
        per = r.per_joint_error_cm()
        worst = np.argsort(per)[::-1][:4]
        print(f"  {name}: {len(joints)} frames, body fit bone-length RMS {fit_rms * 100:.2f} cm\n"
              f"    solve_ik err {r.mean_error_cm:.2f} cm (analytic {a.mean_error_cm:.2f}, max_turn 89: "
              f"{lo.mean_error_cm:.2f}) | LBFGS-100 err {b.mean_error_cm:.2f} cm | reachable targets: "
              f"solve_ik {rf.mean_error_cm:.3f} cm, LBFGS-100 {bf.mean_error_cm:.3f} cm\n"
              "    worst joints (cm): " + ", ".join(f"{JOINT_NAMES[j]} {per[j]:.2f}" for j in worst))
    speedup = base.time / ours.time
    print(f"  total {ours.frames} frames: solve_ik {ours.time:.3f} s ({ours.frames / ours.time:.0f} frames/s; "
          f"analytic only {analytic.time:.3f} s), LBFGS-100 baseline {base.time:.3f} s -> speedup x{speedup:.1f} "
          f"(analytic only x{base.time / analytic.time:.0f}; 10 refinement steps x{base.time / ours10.time:.1f}, "
          f"err {ours10.err_cm:.3f} cm)")
    print(f"  joint error on the fitted body: solve_ik {ours.err_cm:.3f} cm (analytic {analytic.err_cm:.3f}, "
          f"max_turn 89: {loose.err_cm:.3f}) vs baseline {base.err_cm:.3f} cm; bone-direction turn p99 "
          f"{ours.turn_p99:.1f} deg vs baseline {base.turn_p99:.1f} deg")
    print(f"  reachable targets (body fits): solve_ik {ours_fit.err_cm:.4f} cm vs baseline {base_fit.err_cm:.4f} cm")
    try:
        archives = _archive_table(body, quick)
    except Exception as exc:  # archives absent
        print(f"  per-archive table skipped ({exc})")
        archives = {}
    return {**archives, "ik_speedup": speedup, "ik_speedup_10_steps": base.time / ours10.time,
            "ik_err_cm_10_steps": ours10.err_cm, "ik_err_cm": ours.err_cm, "ik_baseline_err_cm": base.err_cm,
            "ik_analytic_err_cm": analytic.err_cm, "ik_analytic_speedup": base.time / analytic.time,
            "ik_max_turn_89_err_cm": loose.err_cm, "ik_bone_turn_p99_deg": ours.turn_p99,
            "ik_baseline_bone_turn_p99_deg": base.turn_p99, "ik_reachable_err_cm": ours_fit.err_cm,
            "ik_baseline_reachable_err_cm": base_fit.err_cm, "ik_time_s": ours.time,
            "ik_baseline_time_s": base.time, "ik_frames": ours.frames, "ik_clips": len(clips)}
