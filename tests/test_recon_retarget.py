"""SA-VAE evaluation (`eval recon`), retargeting (SA-VAE and naive, `retarget`), betas from
measurements / shape texts, and the SA-VAE vs naive comparison. A tiny SA-VAE is trained on the
`tiny_dataset` fixture (real clips, real builder) for a few steps."""
import json

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError

RUN_CLIP = "dataset-1_run_happy_001"  # 93 frames; the tiny dataset also holds its augmented copy
RECON_KEYS = {"mpjpe_mm", "mpjpe_local_mm", "bone_err_mm", "penetrate_cm", "float_cm", "skate_pct", "dyn_stable_pct",
              "penetrate_all_cm", "float_all_cm", "skate_joints_pct", "code_usage_pct", "clips"}


@pytest.fixture(scope="module")
def body():
    from shapemove.core.body.load import load_body_model

    return load_body_model(None)


@pytest.fixture(scope="module")
def vae_run(tiny_dataset, body, tmp_path_factory):
    """A tiny SA-VAE trained for 20 steps on the tiny dataset (a few seconds)."""
    from shapemove.core.models.savae import SAVAEConfig, TrainSettings
    from shapemove.core.train.train_vae import train_vae

    cfg = SAVAEConfig(width=16, depth=1, shape_hidden=16,
                      train=TrainSettings(steps=20, batch_size=4, lr=1e-2, warmup_steps=2, log_every=10, val_every=20,
                                          val_batches=1, ckpt_every=1000))
    out = tmp_path_factory.mktemp("savae_run")
    train_vae(tiny_dataset, out, cfg, body=body, device="cpu", verbose=False)
    return out


@pytest.fixture(scope="module")
def vae(vae_run, body):
    from shapemove.core.generation.retarget import load_vae

    return load_vae(vae_run, body)


@pytest.fixture(scope="module")
def run_bvh(mocap_root):
    return mocap_root / "bandai" / "dataset-1" / "data" / f"{RUN_CLIP}.bvh"


def _height(body, betas) -> float:
    from shapemove.core.body.measure import measure

    return measure(body, betas)["height_cm"]


# -- betas from measurements and shape texts ----------------------------------------------------------

def test_betas_for_measurements(openbody):
    from shapemove.core.body.measure import MEASUREMENTS, measure
    from shapemove.core.body.shape_from_measurements import betas_for_measurements, fast_measure

    b = np.random.default_rng(1).standard_normal((2, 10))
    m = measure(openbody, b)
    assert np.allclose(fast_measure(openbody, b, MEASUREMENTS), np.stack([m[k] for k in MEASUREMENTS], 1), atol=1e-3)
    for h in (190.0, 155.0):
        betas = betas_for_measurements(openbody, {"height_cm": h})
        assert betas.shape == (10,) and abs(_height(openbody, betas) - h) < 1.0
        assert np.linalg.norm(betas) < 3.0                   # the prior keeps the other directions small
    betas = betas_for_measurements(openbody, {"height_cm": 180.0, "waist_cm": 100.0})
    got = measure(openbody, betas)
    assert abs(got["height_cm"] - 180) < 1.0 and abs(got["waist_cm"] - 100) < 1.0
    with pytest.raises(ShapeMoveError, match="unknown measurement"):
        betas_for_measurements(openbody, {"shoe_size": 44})
    with pytest.raises(ShapeMoveError, match="plausible"):
        betas_for_measurements(openbody, {"height_cm": 400})


def test_targets_from_shape_text(openbody):
    from shapemove.core.body.shape_from_measurements import betas_from_shape_text, targets_from_shape_text

    t = targets_from_shape_text("A person standing 182 cm tall, with a chest circumference of 101 cm, "
                                "a waist circumference of 90 cm, an arm length of 55 cm.")
    assert t == {"height_cm": 182.0, "chest_cm": 101.0, "waist_cm": 90.0, "arm_length_cm": 55.0}
    t = targets_from_shape_text("a tall, heavy-set man")          # band middles: 185 cm, waist/height 0.565
    assert t["height_cm"] == 185.0 and t["waist_cm"] == pytest.approx(0.565 * 185)
    assert targets_from_shape_text("A very short, slim woman") == {"height_cm": 150.0, "waist_cm": pytest.approx(61.5)}
    assert targets_from_shape_text("an average-sized person") == {}
    assert np.all(betas_from_shape_text(openbody, "an average-sized person") == 0)
    for bad in ("a blue banana", "   "):
        with pytest.raises(ShapeMoveError):
            targets_from_shape_text(bad)


# -- eval recon ---------------------------------------------------------------------------------------

def test_eval_recon(tiny_dataset, vae_run, body):
    from shapemove.core.eval.recon import eval_recon
    from shapemove.core.train.motion_dataset import read_split

    seen, rows = [], []
    r = eval_recon(tiny_dataset, vae_run, split="test", body=body, progress=lambda f, cid: seen.append(f), per_clip=rows)
    ids = read_split(tiny_dataset, "test")
    assert set(r) == RECON_KEYS | {"ground_truth"} and set(r["ground_truth"]) == RECON_KEYS
    assert all(np.isfinite(r[k]) for k in RECON_KEYS) and r["clips"] == len(ids) >= 1
    gt = r["ground_truth"]
    assert gt["mpjpe_mm"] == 0.0 and gt["code_usage_pct"] is None
    assert gt["bone_err_mm"] < 0.1             # the dataset's motion is FK of the clip's own body
    assert r["mpjpe_mm"] > 0 and 0 < r["code_usage_pct"] <= 100
    assert seen[-1] == 1.0 and [row["id"] for row in rows] == ids
    assert all(row["frames"] % 4 == 0 for row in rows)
    n = np.array([row["frames"] for row in rows])           # pooled = frame-weighted mean of the clips
    assert r["mpjpe_mm"] == pytest.approx((n * [row["mpjpe_mm"] for row in rows]).sum() / n.sum())


def test_cli_eval_recon(tiny_dataset, vae_run, tmp_path, capsys):
    from shapemove.cli import main
    from shapemove.core.models.savae import SAVAEConfig
    from shapemove.core.train.checkpoint import make_metadata, save_checkpoint

    out = tmp_path / "recon.json"
    assert main(["eval", "recon", "--data", str(tiny_dataset), "--checkpoint", str(vae_run / "savae.pt"),
                 "--json", str(out), "--max-clips", "1", "--quiet"]) == 0
    res = json.loads(out.read_text())
    assert set(res) == RECON_KEYS | {"ground_truth"} and res["clips"] == 1 and res["ground_truth"]["mpjpe_mm"] == 0
    text = capsys.readouterr().out
    assert "ground truth" in text and "MPJPE" in text and not list(tmp_path.glob("*.tmp"))
    # bad inputs: one-line errors, exit code 2
    other = save_checkpoint(tmp_path / "tma.pt", {"model": {}},
                            make_metadata("tma", SAVAEConfig().to_dict(), "openbody-v1", np.zeros(263), np.ones(263)))
    for argv in (["--data", str(tiny_dataset), "--checkpoint", str(other)],
                 ["--data", str(tmp_path / "nowhere"), "--checkpoint", str(vae_run)],
                 ["--data", str(tiny_dataset), "--checkpoint", str(tmp_path)]):
        assert main(["eval", "recon", *argv, "--json", str(out), "--quiet"]) == 2
    assert "expected 'savae'" in capsys.readouterr().err


# -- retargeting --------------------------------------------------------------------------------------

def test_retarget_through_savae(run_bvh, tiny_dataset, vae, body):
    from shapemove.core.body.shape_from_measurements import betas_from_shape_text
    from shapemove.core.eval.bones import bone_lengths, target_bone_lengths
    from shapemove.core.generation.retarget import decode_tokens, retarget
    from shapemove.core.scene.motion_file import validate

    tall_b = betas_from_shape_text(body, "A person standing 190 cm tall")
    short_b = betas_from_shape_text(body, "A person standing 155 cm tall")
    tall, short = retarget(run_bvh, vae, body, tall_b), retarget(run_bvh, vae, body, short_b)
    total = []                                             # summed bone length of the posed body (m)
    for m, b in ((tall, tall_b), (short, short_b)):
        validate(m)
        assert np.array_equal(m.betas, b) and m.num_frames == 4 * len(m.tokens) == 92  # 93 frames -> 92 rows
        with torch.no_grad():                              # the body Blender poses: the target's bones
            fk = body.forward(torch.as_tensor(b)[None], torch.as_tensor(m.poses), torch.as_tensor(m.transl)).joints
        assert np.abs(bone_lengths(fk[:, :22]) - target_bone_lengths(body, torch.as_tensor(b)[None])).max() < 1e-4
        assert np.abs(fk[:, :22].numpy() - m.joints).mean() < 0.05       # IK follows the decoded joints
        total.append(bone_lengths(fk[:, :22]).sum(1).mean())
    assert total[0] > total[1] + 0.3                                             # 190 cm vs 155 cm body
    assert np.array_equal(tall.tokens, short.tokens)        # same motion tokens, decoded for two bodies
    assert np.abs(tall.features - short.features).max() > 0  # the decoder saw the new betas
    # without the search, the tokens are the builder's canonical features of that clip, encoded
    x = np.load(tiny_dataset / "norm_joint_vecs" / f"{RUN_CLIP}.npy")[:92]
    with torch.no_grad():
        _, idx = vae.encode(vae.normalize(torch.as_tensor(x))[None])
    assert np.array_equal(retarget(run_bvh, vae, body, tall_b, search=False).tokens, idx[0].numpy())
    again = decode_tokens([int(t) for t in tall.tokens], vae, body, tall_b)  # re-decodable from its tokens
    assert np.allclose(again.features, tall.features, atol=1e-5)


def test_retarget_plants_the_source_contacts(run_bvh, vae, body):
    """The retargeted feet stay where the SOURCE's feet were in contact (known contacts, not the
    decoder's): the motion's contacts are the source's, and a planted foot joint barely moves."""
    from shapemove.core.body.shape_from_measurements import betas_from_shape_text
    from shapemove.core.generation.retarget import retarget, source_contacts, source_joints
    from shapemove.core.motion.contacts import runs

    b = betas_from_shape_text(body, "A person standing 190 cm tall")
    m = retarget(run_bvh, vae, body, b)
    src = source_contacts(source_joints(run_bvh, body)[0])
    assert src[:, 2:].sum() > 20                                   # a run: the toes touch down many times
    np.testing.assert_array_equal(m.contacts, src[:m.num_frames])
    with torch.no_grad():
        fk = body.forward(torch.as_tensor(b)[None], torch.as_tensor(m.poses), torch.as_tensor(m.transl)).joints
    fk = fk[:, :22].double().numpy()
    steps = lambda j: np.concatenate([np.linalg.norm(np.diff(j[s:e, jid][:, [0, 2]], axis=0), axis=1)  # noqa: E731
                                      for k, jid in enumerate((7, 8, 10, 11)) for s, e in runs(m.contacts[:, k])])
    # planted: the median step of a foot joint in contact is < 1 mm/frame, where the decoded joints
    # (20 training steps: a poor decoder) slide > 5 mm/frame; the largest steps come from frames
    # where the decoded pelvis runs further than the leg reaches (IK compromise)
    assert np.median(steps(fk)) < 1e-3 < 5e-3 < np.median(steps(m.network_joints.astype(np.float64)))
    free = retarget(run_bvh, vae, body, b, plant_source_contacts=False)    # the decoder's own contacts
    assert not np.array_equal(free.contacts, m.contacts)
    assert m.contacts_measured and not free.contacts_measured


def test_redecoding_a_retargeted_motion_plants_the_source_contacts(run_bvh, vae, body, tmp_path):
    """A slider change re-decodes a retargeted motion: the source's contacts survive the motion file
    and are planted on the new body, not the decoder's guesses; a generated motion (decoder
    contacts) re-decodes with the decoder's contacts for the new body."""
    from shapemove.core.generation.decode import redecode
    from shapemove.core.generation.retarget import retarget
    from shapemove.core.scene.motion_file import load_motion, save_motion

    m = retarget(run_bvh, vae, body, np.zeros(10, np.float32))
    back = load_motion(save_motion(tmp_path / "r.npz", m))
    assert back.contacts_measured
    tall = np.zeros(10, np.float32)
    tall[0] = 2.0
    r = redecode(back, vae, body, tall)
    assert r.contacts_measured
    np.testing.assert_array_equal(r.contacts, m.contacts)
    np.testing.assert_array_equal(r.tokens, m.tokens)
    free = retarget(run_bvh, vae, body, np.zeros(10, np.float32), plant_source_contacts=False)
    back = load_motion(save_motion(tmp_path / "f.npz", free))
    assert not back.contacts_measured
    r = redecode(back, vae, body, tall)
    assert not r.contacts_measured and not np.array_equal(r.contacts, m.contacts)


def test_take_error_is_the_root_aligned_joint_distance(run_bvh, vae, body):
    """take_fidelity: the codes' decoded joints against the take's, root-aligned, in mm; the worst
    second is the largest one-second mean. Hand-derived: one joint of 22 moved 10 cm up in every
    frame is 100 / 22 mm per frame; a window's mean."""
    from shapemove.core.generation.decode import decode_features
    from shapemove.core.generation.retarget import encode_take, processor, source_joints
    from shapemove.core.generation.take_fidelity import take_error_mm, worst_second_mm

    arrays = processor(body).process(source_joints(run_bvh, body)[0])
    codes = encode_take(vae, arrays["norm_joint_vecs"], search=False)
    with torch.no_grad():
        own = decode_features(codes, vae, arrays["betas"]).numpy()
        assert np.abs(take_error_mm(codes, vae, arrays["betas"], own)).max() < 1e-3     # the decoding itself: 0
        moved = own.copy()
        moved[:, 4 + 1] += 0.1       # ric data (joints 1..21, x y z from column 4): joint 1 (left hip) 10 cm up
        np.testing.assert_allclose(take_error_mm(codes, vae, arrays["betas"], moved), 100 / 22, rtol=1e-4)
        real = take_error_mm(codes, vae, arrays["betas"], arrays["new_joint_vecs"])
    assert real.shape == (4 * len(codes),) and real.mean() > 10   # 20 training steps: far from the take
    err = np.r_[np.zeros(10), np.full(20, 30.0), np.zeros(10)]
    assert worst_second_mm(err, frames=20) == pytest.approx(30.0)
    assert worst_second_mm(err, frames=40) == pytest.approx(15.0) == worst_second_mm(err, frames=100)
    assert worst_second_mm(err, frames=30) == pytest.approx(20.0)
    with pytest.raises(ShapeMoveError, match="take's features"):
        take_error_mm(codes, vae, arrays["betas"], own[:10])


def test_retarget_falls_back_to_the_takes_rotations_when_the_codes_miss_it(run_bvh, vae, body):
    """With ``fallback_mm`` the codes are checked on the subject's own body first: under the
    threshold the SA-VAE's motion (tokens); over it the take's own rotations on the new body, its
    feet planted on the source's contacts, the bones the new body's, and a warning."""
    from shapemove.core.body.shape_from_measurements import betas_from_shape_text
    from shapemove.core.eval.bones import bone_lengths, target_bone_lengths
    from shapemove.core.generation.retarget import (encode_take, naive_retarget, processor, retarget, source_contacts,
                                                    source_joints)
    from shapemove.core.generation.take_fidelity import take_error_mm, worst_second_mm
    from shapemove.core.motion.contacts import runs

    b = betas_from_shape_text(body, "A person standing 190 cm tall")
    joints = source_joints(run_bvh, body)[0]
    arrays = processor(body).process(joints)
    codes = encode_take(vae, arrays["norm_joint_vecs"], arrays["betas"], arrays["new_joint_vecs"])
    with torch.no_grad():
        worst = worst_second_mm(take_error_mm(codes, vae, arrays["betas"], arrays["new_joint_vecs"]))
    kept = retarget(run_bvh, vae, body, b, fallback_mm=worst + 1)
    assert np.array_equal(kept.tokens, codes) and not kept.notes
    m = retarget(run_bvh, vae, body, b, fallback_mm=worst - 1)
    assert m.tokens is None and m.num_frames == len(joints) and np.array_equal(m.betas, b)
    assert len(m.notes) == 1 and f"{worst:.0f} mm" in m.notes[0]
    src = source_contacts(joints)       # planted; a heel the foot rolls off where the leg cannot reach is released
    assert m.contacts_measured and not (m.contacts > src).any() and (m.contacts == src).mean() > 0.9
    with torch.no_grad():
        fk = body.forward(torch.as_tensor(b)[None], torch.as_tensor(m.poses), torch.as_tensor(m.transl)).joints
    fk = fk[:, :22].double().numpy()
    assert np.abs(bone_lengths(fk) - target_bone_lengths(body, torch.as_tensor(b)[None])).max() < 1e-4
    steps = np.concatenate([np.linalg.norm(np.diff(fk[s:e, jid][:, [0, 2]], axis=0), axis=1)
                            for k, jid in enumerate((7, 8, 10, 11)) for s, e in runs(m.contacts[:, k])])
    assert np.median(steps) < 1e-3                                   # planted feet stay put
    # the pose is the take's: within 2 cm of the naive retarget (the same rotations on the same body)
    # by what a turn about the vertical keeps (each joint's height over the root and its horizontal
    # distance from it: the fallback starts facing +Z, naive keeps the capture's heading), where the
    # tiny codec's decoding is much further off
    def rel(j):
        d = j - j[:, :1]
        return np.stack([d[..., 1], np.linalg.norm(d[..., [0, 2]], axis=-1)], -1)
    naive = naive_retarget(run_bvh, body, b)
    assert np.abs(rel(fk) - rel(naive.joints)).mean() < 0.02
    n = kept.num_frames
    assert np.abs(rel(kept.joints) - rel(naive.joints[:n])).mean() > 0.03
    j = m.joints      # ... and it starts as a decoded take does: the root over the origin, facing +Z
    facing = np.cross((j[0, 1] - j[0, 2]) + (j[0, 16] - j[0, 17]), [0.0, 1.0, 0.0])
    assert np.abs(j[0, 0, [0, 2]]).max() < 0.01 and abs(np.degrees(np.arctan2(facing[0], facing[2]))) < 3
    assert m.remakeable and kept.remakeable


def test_a_planted_take_is_planted_again_for_a_new_body(run_bvh, vae, body):
    """A body-shape change on a take played by its own rotations (no tokens to decode) plants it
    again (``replant``): the new body's bones, the stride scaled by the new leg length, the planted
    feet still; the same rotations on the new bones alone (what a slider does without it) slide."""
    from shapemove.core.body.shape_from_measurements import betas_from_shape_text
    from shapemove.core.eval.bones import bone_lengths, target_bone_lengths
    from shapemove.core.generation.retarget import ground_each_frame, replant, retarget
    from shapemove.core.motion.contacts import runs
    from shapemove.core.scene.motion_file import make_motion

    tall, short = (betas_from_shape_text(body, f"A person standing {h} cm tall") for h in (190, 150))
    m = retarget(run_bvh, vae, body, tall, fallback_mm=0.0)          # always by its own rotations
    assert m.tokens is None and m.remakeable

    def fk(x):
        with torch.no_grad():
            return body.forward(torch.as_tensor(x.betas)[None], torch.as_tensor(x.poses),
                                torch.as_tensor(x.transl)).joints[:, :22].double().numpy()

    def slide(x, contacts):
        j = fk(x)
        return np.median(np.concatenate([np.linalg.norm(np.diff(j[s:e, jid][:, [0, 2]], axis=0), axis=1)
                                         for k, jid in enumerate((7, 8, 10, 11)) for s, e in runs(contacts[:, k])]))

    again = replant(m, body, short)
    assert again.tokens is None and again.contacts_measured and again.num_frames == m.num_frames
    assert np.array_equal(again.betas, short) and slide(again, again.contacts) < 1e-3
    assert np.abs(bone_lengths(fk(again)) - target_bone_lengths(body, torch.as_tensor(short)[None])).max() < 1e-4
    path = lambda x: np.linalg.norm(np.diff(fk(x)[:, 0, [0, 2]], axis=0), axis=1).sum()  # noqa: E731
    assert path(again) < 0.9 * path(m)                                 # a shorter body takes shorter strides
    rebased = ground_each_frame(make_motion(body, m.poses, m.transl, short, fps=20.0), body)
    assert slide(rebased, m.contacts) > 3 * max(slide(again, again.contacts), 1e-4)
    with pytest.raises(ShapeMoveError, match="re-planted"):
        replant(retarget(run_bvh, vae, body, tall), body, short)      # tokens: decoded again instead


def test_naive_retarget_keeps_the_rotations_on_the_new_bones(run_bvh, tiny_dataset, body):
    from shapemove.core.body.skeleton import PARENTS
    from shapemove.core.eval.bones import bone_lengths, target_bone_lengths
    from shapemove.core.generation.retarget import naive_retarget
    from shapemove.core.geometry.fk import forward_kinematics
    from shapemove.core.geometry.rotations import axis_angle_to_matrix

    betas = np.load(tiny_dataset / "betas" / f"{RUN_CLIP}_aug.npy")      # a body the builder sampled
    m = naive_retarget(run_bvh, body, betas)
    rest = lambda b: body.rest_joints(torch.as_tensor(b)[None])[0].numpy()  # noqa: E731
    rot = axis_angle_to_matrix(m.poses)
    # the motion's own rotations on the new body's rest skeleton give its joints (root-relative)
    posed = forward_kinematics(rot, rest(betas), PARENTS)[0][:, :22]
    rel = lambda j: j - j[:, :1]  # noqa: E731
    assert np.abs(rel(posed) - rel(m.joints)).max() < 1e-4
    # the same rotations on the subject's fitted body give the subject's clip: the pose is kept
    subject = forward_kinematics(rot, rest(np.load(tiny_dataset / "betas" / f"{RUN_CLIP}.npy")), PARENTS)[0][:, :22]
    assert np.abs(rel(subject) - rel(np.load(tiny_dataset / "new_joints" / f"{RUN_CLIP}.npy"))).max() < 1e-4
    assert np.abs(rel(subject) - rel(m.joints)).max() > 0.01  # ... and the bones did change
    # bones are exactly the new body's, the clip's lowest mesh point is on the floor (one offset)
    err = np.abs(bone_lengths(m.joints) - target_bone_lengths(body, torch.as_tensor(betas)[None]))
    with torch.no_grad():
        verts = body(torch.as_tensor(betas)[None].expand(m.num_frames, -1), torch.as_tensor(m.poses),
                     torch.as_tensor(m.transl)).vertices
    assert err.max() < 1e-5 and float(verts[..., 1].min()) == pytest.approx(0, abs=2e-3)
    # root path scaled by the pelvis-height ratio of the new and the subject's body
    sub = np.load(tiny_dataset / "new_joints" / f"{RUN_CLIP}.npy")
    ph = lambda r: r[0, 1] - r[[7, 8, 10, 11], 1].min()  # noqa: E731
    s = ph(rest(betas)) / ph(rest(np.load(tiny_dataset / "betas" / f"{RUN_CLIP}.npy")))
    step = lambda j: j[:, 0, [0, 2]] - j[0, 0, [0, 2]]  # noqa: E731
    assert np.allclose(step(m.joints), s * step(sub), atol=1e-4) and abs(s - 1) > 0.01


def test_naive_retarget_grounded_per_frame_stands_on_the_floor_in_every_frame(run_bvh, tiny_dataset, body):
    from shapemove.core.generation.retarget import naive_retarget

    betas = np.load(tiny_dataset / "betas" / f"{RUN_CLIP}_aug.npy")
    clip, frame = naive_retarget(run_bvh, body, betas), naive_retarget(run_bvh, body, betas, ground="frame")

    def lowest(m):  # the full mesh (not the ground probe the grounding uses), per frame
        with torch.no_grad():
            v = body(torch.as_tensor(betas)[None].expand(m.num_frames, -1), torch.as_tensor(m.poses),
                     torch.as_tensor(m.transl)).vertices
        return v[..., 1].min(1).values.numpy()

    low_clip, low_frame = lowest(clip), lowest(frame)
    assert np.abs(low_frame).max() < 2e-3                       # every frame on the floor
    assert low_clip.min() == pytest.approx(0, abs=2e-3) and low_clip.max() > 0.01   # one offset: hovers
    assert np.array_equal(clip.poses, frame.poses)              # only the height changed
    assert np.allclose(clip.transl[:, [0, 2]], frame.transl[:, [0, 2]])
    with pytest.raises(ShapeMoveError, match="ground"):
        naive_retarget(run_bvh, body, betas, ground="floor")


def test_compare_retargeting(tiny_dataset, vae_run, body):
    from shapemove.core.body.shape_from_measurements import betas_for_measurements
    from shapemove.core.eval.retarget_compare import KEYS, compare_retargeting

    targets = [betas_for_measurements(body, {"height_cm": h}) for h in (190.0, 155.0)]
    r = compare_retargeting(tiny_dataset, vae_run, ["cmu_09_01"], targets, body=body)
    assert set(r) == {"savae", "auto", "naive", "naive_frame", "swap", "source"}
    for name in r:
        extra = {"fallbacks"} if name == "auto" else set()
        assert set(r[name]) == set(KEYS) | {"clips", "bodies"} | extra
        assert r[name]["bodies"] == (1 if name == "source" else 2) and all(np.isfinite(r[name][k]) for k in KEYS)
    assert r["naive"]["bone_err_mm"] < 0.01 < r["savae"]["bone_err_mm"]
    # the tiny codec misses the take: "auto" moves it by its own rotations (the new bones exactly)
    assert r["auto"]["fallbacks"] == 1 and r["auto"]["bone_err_mm"] < 0.01
    kept = compare_retargeting(tiny_dataset, vae_run, ["cmu_09_01"], targets, body=body, fallback_mm=1e9)
    assert kept["auto"]["fallbacks"] == 0 and kept["auto"] == {**kept["savae"], "fallbacks": 0}
    assert r["source"]["bone_err_mm"] < 0.01      # the capture's own FK on its own fitted body
    with pytest.raises(ShapeMoveError, match="no clip"):
        compare_retargeting(tiny_dataset, vae_run, ["no_such_clip"], targets, body=body)


def test_cli_retarget(run_bvh, vae_run, body, tmp_path, capsys):
    from shapemove.cli import main
    from shapemove.cli.retarget import run
    from shapemove.core.models.savae import SAVAEConfig
    from shapemove.core.scene.motion_file import load_motion
    from shapemove.core.train.checkpoint import make_metadata, save_checkpoint

    out = tmp_path / "tall.npz"
    assert main(["retarget", "--motion", str(run_bvh), "--shape-text", "A person standing 190 cm tall",
                 "--checkpoint", str(vae_run), "--out", str(out), "--no-fallback"]) == 0
    m = load_motion(out)
    assert m.tokens is not None and abs(_height(body, m.betas) - 190) < 1.0
    capsys.readouterr()
    # the 20-step codec misses the take by far more than LOST_TAKE_MM: by default its own rotations
    assert main(["retarget", "--motion", str(run_bvh), "--shape-text", "A person standing 190 cm tall",
                 "--checkpoint", str(vae_run), "--out", str(out)]) == 0
    assert load_motion(out).tokens is None and "the take's own rotations, feet planted" in capsys.readouterr().out
    assert main(["retarget", "--motion", str(run_bvh), "--betas", "1,0.5", "--naive", "--out", str(tmp_path / "n.npz")]) == 0
    assert np.allclose(load_motion(tmp_path / "n.npz").betas[:3], [1, 0.5, 0])
    capsys.readouterr()

    def args(**kw):
        import argparse

        base = dict(motion=run_bvh, betas=None, shape_text=None, checkpoint=vae_run, out=tmp_path / "x.npz",
                    naive=False, body_model=None, no_fallback=False)
        return argparse.Namespace(**{**base, **kw})

    other = save_checkpoint(tmp_path / "t5.pt", {"model": {}},    # a checkpoint of another kind
                            make_metadata("t5", SAVAEConfig().to_dict(), body.name, np.zeros(263), np.ones(263)))
    bad = [(dict(motion=tmp_path / "missing.bvh", betas="1"), "not found"),
           (dict(betas="1", shape_text="A person standing 190 cm tall"), "exactly one"),
           (dict(), "exactly one"),
           (dict(shape_text="a purple teapot"), "cannot read a body shape"),
           (dict(betas="1", out=tmp_path / "x.bvh"), r"\.npz"),
           (dict(betas="1", checkpoint=tmp_path / "nothing"), "not found"),
           (dict(betas="1", checkpoint=other), "expected 'savae'")]
    for kw, message in bad:
        with pytest.raises(ShapeMoveError, match=message):
            run(args(**kw))
