"""The dataset builder on real clips: layout, shape-aware vs normalized motion, resumability,
failure reporting."""
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch

from shapemove.core.body.fit import bone_lengths
from shapemove.core.data.build import build_dataset
from shapemove.core.motion.features import joints_from_features


def _ids(root, split):
    return (Path(root) / f"{split}.txt").read_text().split()


def test_layout_and_contents(tiny_dataset, openbody):
    root = Path(tiny_dataset)
    metas = [json.loads(ln) for ln in (root / "meta.jsonl").read_text().splitlines()]
    ids = [m["id"] for m in metas]
    assert len(ids) >= 12 and sorted(ids) == sorted(_ids(root, "train") + _ids(root, "val") + _ids(root, "test"))
    assert np.load(root / "Mean.npy").shape == (263,) and (np.load(root / "Std.npy") > 0).all()
    for m in metas:
        cid = m["id"]
        j = np.load(root / "new_joints" / f"{cid}.npy")
        f = np.load(root / "new_joint_vecs" / f"{cid}.npy")
        nj = np.load(root / "norm_joints" / f"{cid}.npy")
        assert j.shape == nj.shape and j.shape[1:] == (22, 3) and f.shape == (len(j) - 1, 263)
        assert np.load(root / "poses" / f"{cid}.npy").shape == (len(j), 24, 3)
        assert (root / "texts" / f"{cid}.txt").read_text().strip()
        shape_lines = (root / "shape_texts" / f"{cid}.txt").read_text().splitlines()
        assert shape_lines[0].startswith("A person standing") and shape_lines[1].startswith(("a ", "an "))
        assert m["fps"] == 20 and m["frames"] == len(j) and m["licence"]
        # foot contacts: stored per frame, and they are the features' 4 contact channels
        c = np.load(root / "contacts" / f"{cid}.npy")
        assert c.dtype == np.uint8 and c.shape == (len(j), 4) and set(np.unique(c)) <= {0, 1}
        np.testing.assert_array_equal(f[:, 259:263], c[:-1][:, [0, 2, 1, 3]])
        # the features keep the heights: decoding them gives the stored joints' heights back
        np.testing.assert_allclose(joints_from_features(f)[..., 1], j[:-1, :, 1], atol=1e-4)


def test_feet_stand_on_the_mesh_soles(tiny_dataset, openbody):
    """Checked on the full posed mesh (not the builder's sole probe): the file's joints are FK of its
    (betas, poses, transl); on frames with a foot contact the lowest vertex is on the floor; no
    frame has the mesh under the floor; planted feet do not slide."""
    root = Path(tiny_dataset)
    lows, contact_lows, slides = [], [], []
    for cid in _ids(root, "train") + _ids(root, "val") + _ids(root, "test"):
        j = np.load(root / "new_joints" / f"{cid}.npy")
        c = np.load(root / "contacts" / f"{cid}.npy").astype(bool)
        with torch.no_grad():
            out = openbody(torch.as_tensor(np.load(root / "betas" / f"{cid}.npy"))[None].expand(len(j), -1),
                           torch.as_tensor(np.load(root / "poses" / f"{cid}.npy")),
                           torch.as_tensor(np.load(root / "transl" / f"{cid}.npy")))
        assert np.abs(out.joints[:, :22].numpy() - j).max() < 1e-3, cid
        low = out.vertices[..., 1].min(1).values.numpy()
        lows.append(low)
        contact_lows.append(low[c.any(1)])
        step = np.linalg.norm(np.diff(j[:, [7, 8, 10, 11]][..., [0, 2]], axis=0), axis=-1)  # (T-1,4)
        slides.append(step[c[:-1] & c[1:]])
    low, on, slide = np.concatenate(lows), np.concatenate(contact_lows), np.concatenate(slides)
    assert on.size > 0.3 * low.size
    assert np.abs(on).max() < 0.002 and np.abs(on).mean() < 0.0005        # soles on the floor
    assert low.min() > -0.002 and np.maximum(-low, 0).mean() < 0.0005       # paper penetrate <= 0.05 cm
    assert np.median(slide) < 0.002 and np.mean(slide) < 0.005              # planted: < 2 mm/frame typical


def test_shape_aware_bones_match_the_fitted_body_and_normalized_the_canonical(tiny_dataset, openbody):
    root = Path(tiny_dataset)
    canon = bone_lengths(openbody.rest_joints(None)[0].numpy()[:22])
    for cid in _ids(root, "train")[:4]:
        betas = np.load(root / "betas" / f"{cid}.npy")
        own = bone_lengths(openbody.rest_joints(torch.as_tensor(betas)[None])[0].numpy()[:22])
        shaped = bone_lengths(np.load(root / "new_joints" / f"{cid}.npy"))
        normal = bone_lengths(np.load(root / "norm_joints" / f"{cid}.npy"))
        np.testing.assert_allclose(shaped, np.broadcast_to(own, shaped.shape), atol=1e-4)
        np.testing.assert_allclose(normal, np.broadcast_to(canon, normal.shape), atol=1e-4)
        # same rotations: the 6D rotation block of both feature sets is identical
        fs = np.load(root / "new_joint_vecs" / f"{cid}.npy")
        fn = np.load(root / "norm_joint_vecs" / f"{cid}.npy")
        np.testing.assert_allclose(fs[:, 67:193], fn[:, 67:193], atol=1e-5)
        # features decode back to the stored joints (up to the canonical placement of frame 0)
        rec = joints_from_features(fs)
        np.testing.assert_allclose(bone_lengths(rec), shaped[1:], atol=1e-3)


def test_augmented_copies_are_on_other_bodies(tiny_dataset):
    root = Path(tiny_dataset)
    metas = [json.loads(ln) for ln in (root / "meta.jsonl").read_text().splitlines()]
    aug = [m for m in metas if "augmented_from" in m]
    assert aug, "Bandai clips in the tiny set should get augmented copies"
    bodies = {np.load(root / "betas" / f"{m['id']}.npy").tobytes() for m in aug}
    assert len(bodies) == len(aug), "every augmented copy gets its own body"
    for m in aug:
        src = m["augmented_from"]
        assert not np.allclose(np.load(root / "betas" / f"{m['id']}.npy"), np.load(root / "betas" / f"{src}.npy"))
        assert m["split"] == next(x["split"] for x in metas if x["id"] == src)
        # stride follows leg length: the root path scales with the pelvis height
        a, b = np.load(root / "new_joints" / f"{m['id']}.npy"), np.load(root / "new_joints" / f"{src}.npy")
        ratio = np.ptp(a[:, 0, [0, 2]], 0).max() / max(np.ptp(b[:, 0, [0, 2]], 0).max(), 1e-6)
        height_ratio = a[:, 0, 1].mean() / b[:, 0, 1].mean()
        assert ratio == pytest.approx(height_ratio, rel=0.15)


def test_rerun_skips_finished_clips_and_reports_failures(mocap_root, tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    bvh = Path(mocap_root) / "bandai" / "dataset-2" / "data" / "dataset-2_walk_masculine_003.bvh"
    shutil.copy(bvh, src / "walk.bvh")
    (src / "walk.txt").write_text("a man walks forward.\n")
    (src / "broken.bvh").write_text("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n")
    out = tmp_path / "out"
    first = build_dataset([src], out, verbose=False, ik_refine_iters=0)
    assert first.built == 1 and len(first.failures) == 1
    cid, why = first.failures[0]
    assert cid == "broken" and len(why) > 10 and "Traceback" not in why
    assert (out / "texts" / "walk.txt").read_text() == "a man walks forward.\n"
    stamp = (out / "new_joints" / "walk.npy").stat().st_mtime_ns
    again = build_dataset([src], out, verbose=False, ik_refine_iters=0)
    assert again.built == 0 and again.skipped_done == 1
    assert (out / "new_joints" / "walk.npy").stat().st_mtime_ns == stamp
    report = (out / "build_report.txt").read_text()   # both runs' reports, the first run's first
    assert report.startswith("clips built: 1 (") and "clips built: 0 (+0 augmented), already done: 1" in report
    assert report.count("failed: 1") == 2
    sharded = build_dataset([src], tmp_path / "sharded", verbose=False, ik_refine_iters=0, shard=(1, 2))
    assert (tmp_path / "sharded" / "build_report.shard-1-of-2.txt").read_text() == sharded.summary() + "\n"
    assert not (tmp_path / "sharded" / "build_report.txt").exists()   # a later run cannot overwrite a shard's


def test_no_clips_is_a_clear_error(tmp_path):
    from shapemove.core.errors import ShapeMoveError

    with pytest.raises(ShapeMoveError, match="no motion clips"):
        build_dataset([tmp_path], tmp_path / "out", verbose=False)


def test_fitted_bodies_are_plausible_people(tiny_dataset):
    """The betas fitted to real subjects stay in the shape space's range and measure like people."""
    root = Path(tiny_dataset)
    for ln in (root / "meta.jsonl").read_text().splitlines():
        m = json.loads(ln)
        betas = np.load(root / "betas" / f"{m['id']}.npy")
        assert np.abs(betas).max() < 4, (m["id"], betas)
        assert 145 < m["measure"]["height_cm"] < 200 and 55 < m["measure"]["waist_cm"] < 130, m


def test_ik_is_calibrated_per_clip(tiny_dataset):
    """The builder's IK calibrates the rig's torso/girdle joints (core/body/joint_offsets.py): each
    real clip's calibrated points lie closer to the mocap than the joint centres (within 1.5 cm
    over the clips, 2 cm on each: a 30-frame HDM05 squat has 1.8), with offsets within their
    6 cm bound."""
    root = Path(tiny_dataset)
    marker = []
    for ln in (root / "meta.jsonl").read_text().splitlines():
        m = json.loads(ln)
        if "augmented_from" in m:
            continue
        assert m["ik_marker_error_cm"] <= 2.0, m["id"]
        assert m["ik_marker_error_cm"] < m["ik_error_cm"], m["id"]
        assert 0 < m["ik_offset_max_cm"] <= 6.0 + 1e-6, m["id"]
        marker.append(m["ik_marker_error_cm"])
    assert len(marker) >= 12 and np.mean(marker) <= 1.5


def test_a_take_too_short_to_train_on_is_built_for_the_library_only(mocap_root, tmp_path):
    """A single hop (14 frames at 20 fps, under ``MIN_FRAMES``) of a training subject is built whole
    into the ``library`` split: no split list holds it, so nothing trains or is judged on it, and
    the motion library takes it; the same of a held-out subject (HDM05 dg) is not built at all."""
    from shapemove.core.data.build import LIBRARY_SPLIT, MIN_FRAMES, TAKE_MIN_FRAMES
    from shapemove.core.data.library_build import library_metas

    kept, held_out = "HDM_bd_hopBothLegs1hops_001_120", "HDM_dg_hopBothLegs1hops_026_120"
    out = tmp_path / "out"
    report = build_dataset([mocap_root], out, only=[kept, held_out], verbose=False, ik_refine_iters=0)
    assert report.built == 1 and report.splits == {"train": 0, "val": 0, "test": 0, LIBRARY_SPLIT: 1}
    meta = json.loads((out / "meta" / f"{kept}.json").read_text())
    assert meta["split"] == LIBRARY_SPLIT and TAKE_MIN_FRAMES <= meta["frames"] < MIN_FRAMES
    assert np.load(out / "poses" / f"{kept}.npy").shape == (meta["frames"], 24, 3)
    assert all(not _ids(out, s) for s in ("train", "val", "test"))
    assert [cid for cid, _ in report.failures] == [held_out] and "held-out subject" in report.failures[0][1]
    assert [m["id"] for m in library_metas(out)] == [kept]
