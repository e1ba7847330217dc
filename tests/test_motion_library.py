"""The motion library file: what a built dataset's captured takes become, read back bounded."""
from __future__ import annotations

import json

import numpy as np
import pytest

from shapemove.core.data.library_build import FREQUENT_TAKES, build_library, library_metas, thinned
from shapemove.core.data.motion_library import MotionLibrary, short_licence, source_name
from shapemove.core.errors import ShapeMoveError


def test_source_name_and_licence():
    assert source_name("hdm05", "HDM_bd_kickLFront1Reps_003_120") == "HDM05 bd kickLFront 003"
    assert source_name("bandai", "dataset-1_bow_active_001") == "Bandai dataset-1_bow_active_001"
    assert short_licence("CC BY-SA 3.0 (HDM05, Mueller et al. 2007)") == "CC BY-SA 3.0"


def _meta(i, action, dataset="bandai", style="a", frames=100):
    return {"id": f"c{i:03d}", "dataset": dataset, "frames": frames,
            "labels": {"actions": [action] if action else [], "style": style}}


def test_frequent_actions_thinned_round_robin_over_groups():
    walks = [_meta(i, "walk", style="abc"[i % 3], frames=100 + i) for i in range(FREQUENT_TAKES + 30)]
    kicks = [_meta(500 + i, "kick") for i in range(FREQUENT_TAKES + 5)]
    kept = thinned(walks + kicks)
    kept_walks = [m for m in kept if m["labels"]["actions"] == ["walk"]]
    assert len(kept_walks) == FREQUENT_TAKES
    styles = [m["labels"]["style"] for m in kept_walks]
    assert {styles.count(s) for s in "abc"} == {FREQUENT_TAKES // 3}   # each style as often
    # the longest of each group first: no walk kept is shorter than one left out of its group
    for s in "abc":
        left = [m["frames"] for m in walks if m["labels"]["style"] == s and m not in kept_walks]
        assert min(m["frames"] for m in kept_walks if m["labels"]["style"] == s) > max(left)
    assert len([m for m in kept if m["labels"]["actions"] == ["kick"]]) == FREQUENT_TAKES + 5   # all kept


def test_library_of_a_built_dataset(tiny_dataset, tmp_path, openbody):
    import torch

    from shapemove.core.geometry.rotations import matrix_to_axis_angle

    metas = library_metas(tiny_dataset)
    every = [json.loads(p.read_text()) for p in (tiny_dataset / "meta").glob("*.json")]
    assert {m["split"] for m in metas} <= {"train", "val"} and any(m["split"] == "val" for m in metas)
    assert not any(m.get("augmented_from") for m in metas)
    assert len(metas) == sum(1 for m in every if m["split"] != "test" and not m.get("augmented_from"))
    out = tmp_path / "library.npz"
    lib = build_library(tiny_dataset, out, body=openbody)
    back = MotionLibrary.load(out)
    assert len(back) == len(metas) and back.vectors is None
    k = [m["id"] for m in metas].index("HDM_bd_kickLFront1Reps_001_120")
    take = back.take(k)
    assert take.action == "kick" and take.provenance == "captured: HDM05 bd kickLFront 001 (CC BY-SA 3.0)"
    assert "left leg" in " ".join(take.captions)
    poses = np.load(tiny_dataset / "poses" / f"{take.clip_id}.npy")
    transl = np.load(tiny_dataset / "transl" / f"{take.clip_id}.npy")
    assert take.rotations.shape == (len(poses), 24, 3, 3) and take.rotations.dtype == np.float32
    # float16 axis-angle: within a thousandth of a radian (well under a millimetre at the hand)
    assert np.abs(matrix_to_axis_angle(take.rotations) - poses).max() < 3e-3
    rest = openbody.rest_joints(torch.as_tensor(take.betas)[None])[0].numpy()
    np.testing.assert_allclose(take.root, transl + rest[0], atol=1e-5)
    np.testing.assert_array_equal(take.contacts, np.load(tiny_dataset / "contacts" / f"{take.clip_id}.npy"))
    raw = 2 * lib.a["rotations"].nbytes + lib.a["root"].nbytes + lib.a["contacts"].nbytes
    assert out.stat().st_size < 0.5 * raw    # float16 and compressed: under half the float32 arrays


def test_the_shipped_library_is_what_the_builder_makes_now(tiny_dataset):
    """The default model's ``library.npz`` is the dataset builder's output of today's code: every
    take of the tiny dataset's clips that it holds has the rotations, root and contacts that clip is
    built with now (a library written from an older build, before a planting change, held 233 takes
    whose rotations were up to 1.5 rad off and a CMU walk going the other way)."""
    import torch

    from shapemove.core.body.openbody import OpenBody
    from shapemove.core.geometry.rotations import matrix_to_axis_angle
    from shapemove.core.generation.model_bundle import DEFAULT_MODEL_DIR

    lib = MotionLibrary.load(DEFAULT_MODEL_DIR / "library.npz")
    ids = [str(c) for c in lib.a["clip_ids"]]
    body = OpenBody.load()
    shared = [m["id"] for m in library_metas(tiny_dataset) if m["id"] in ids]
    assert len(shared) >= 5, shared
    for cid in shared:
        take = lib.take(ids.index(cid))
        poses = np.load(tiny_dataset / "poses" / f"{cid}.npy")
        assert take.rotations.shape[0] == len(poses), cid
        assert np.abs(matrix_to_axis_angle(take.rotations) - poses).max() < 3e-3, cid
        rest = body.rest_joints(torch.as_tensor(take.betas)[None])[0].numpy()
        root = np.load(tiny_dataset / "transl" / f"{cid}.npy") + rest[0]
        assert np.abs(take.root - root).max() < 1e-4, cid
        np.testing.assert_array_equal(take.contacts, np.load(tiny_dataset / "contacts" / f"{cid}.npy"))


def test_the_shipped_retrieval_memory_is_what_the_builder_makes_now(tiny_dataset):
    """The default model's retrieval memory holds, for each tiny-dataset training clip it keeps, the
    codes the model's SA-VAE gives that clip as the builder makes it today
    (``tools/build_motion_memory.py``; the memory of 2026-11-26 came from an older build)."""
    import torch

    from shapemove.core.generation.model_bundle import DEFAULT_MODEL_DIR
    from shapemove.core.models.motion_memory import MotionMemory
    from shapemove.core.models.savae import load_savae
    from shapemove.core.train.t5_dataset import tokenize_clips

    mem = MotionMemory.load(DEFAULT_MODEL_DIR / "t5")
    shared = [m["id"] for m in library_metas(tiny_dataset) if m["split"] == "train" and m["id"] in mem.clip_ids]
    assert len(shared) >= 4, shared
    with torch.no_grad():
        made = tokenize_clips(load_savae(DEFAULT_MODEL_DIR / "savae.pt"), tiny_dataset, shared)
    for cid in shared:
        np.testing.assert_array_equal(mem.clip_tokens[mem.clip_ids.index(cid)], made[cid], err_msg=cid)


def _write(path, **arrays):
    with open(path, "wb") as f:
        np.savez(f, **arrays)


def test_load_refuses_pickles_and_bad_shapes(tmp_path):
    take = {"poses": np.zeros((8, 24, 3)), "root": np.zeros((8, 3)), "contacts": np.ones((8, 4), np.uint8),
            "betas": np.zeros(10), "fps": 20, "clip_id": "a", "action": "kick", "source": "me", "licence": "CC0",
            "captions": ["a person kicks"]}
    good = MotionLibrary.from_takes([take, take])
    good.save(tmp_path / "ok.npz")
    assert len(MotionLibrary.load(tmp_path / "ok.npz")) == 2
    _write(tmp_path / "pickled.npz", **{**good.a, "captions": np.array([["x"], 1], dtype=object)})
    with pytest.raises(ShapeMoveError, match="pickle"):
        MotionLibrary.load(tmp_path / "pickled.npz")
    _write(tmp_path / "short.npz", **{**good.a, "starts": np.array([0, 8, 20])})
    with pytest.raises(ShapeMoveError, match="rotations must be"):
        MotionLibrary.load(tmp_path / "short.npz")
    _write(tmp_path / "nan.npz", **{**good.a, "root": np.full((16, 3), np.nan, np.float32)})
    with pytest.raises(ShapeMoveError, match="root must be finite"):
        MotionLibrary.load(tmp_path / "nan.npz")
    with pytest.raises(ShapeMoveError, match="MB"):
        MotionLibrary.load(tmp_path / "ok.npz", max_bytes=1000)
    with pytest.raises(ShapeMoveError, match="not found"):
        MotionLibrary.load(tmp_path / "none.npz")


def test_a_take_too_short_to_train_on_is_kept_unless_it_is_a_stride_of_a_gait(tmp_path):
    """Of the clips built for the library only, a single hop is a take; a 0.65 s sprint is one
    stride, not a take to walk on from."""
    import json

    from shapemove.core.data.build import LIBRARY_SPLIT

    (tmp_path / "meta").mkdir()
    for cid, action, split in (("hop", "hop", LIBRARY_SPLIT), ("dash", "sprint", LIBRARY_SPLIT),
                               ("run", "sprint", "train"), ("held", "hop", "test")):
        (tmp_path / "meta" / f"{cid}.json").write_text(json.dumps({"id": cid, "split": split,
                                                                    "labels": {"actions": [action]}}))
    assert [m["id"] for m in library_metas(tmp_path)] == ["hop", "run"]


def test_a_take_whose_root_jumps_from_frame_to_frame_is_left_out(tmp_path):
    """Hand-derived: a root walking 1.4 m/s changes its speed by nothing from frame to frame; one whose
    steps alternate 0.01 and 0.13 m at 20 fps changes it by 2.4 m/s a frame, 48 m/s^2 (a broken
    capture, ``jerky``); a run speeding up 4 m/s in 1 s, 4 m/s^2, is no jump."""
    import json

    from shapemove.core.data.library_build import JERK, jerky

    walk = np.stack([np.arange(40) * 0.07, np.full(40, 0.9), np.zeros(40)], 1)
    broken = walk.copy()
    broken[:, 0] = np.cumsum(np.where(np.arange(40) % 2, 0.13, 0.01))
    speeding = walk.copy()
    speeding[:, 0] = np.cumsum(np.linspace(2.0, 6.0, 40) / 20)
    assert not jerky(walk, 20) and jerky(broken, 20) and not jerky(speeding, 20) and 4 < JERK < 48
    (tmp_path / "meta").mkdir()
    (tmp_path / "transl").mkdir()
    for cid, root in (("steady", walk), ("broken", broken)):
        (tmp_path / "meta" / f"{cid}.json").write_text(json.dumps({"id": cid, "split": "train", "fps": 20,
                                                                    "labels": {"actions": ["walk"]}}))
        np.save(tmp_path / "transl" / f"{cid}.npy", root)
    assert [m["id"] for m in library_metas(tmp_path)] == ["steady"]


def test_the_shipped_library_holds_no_take_whose_root_jumps():
    from shapemove.core.data.library_build import jerky
    from shapemove.core.generation.model_bundle import DEFAULT_MODEL_DIR

    lib = MotionLibrary.load(DEFAULT_MODEL_DIR / "library.npz")
    starts, root, fps = lib.a["starts"], lib.a["root"], lib.a["fps"]
    assert len(starts) > 700
    assert not [str(c) for k, c in enumerate(lib.a["clip_ids"]) if jerky(root[starts[k]:starts[k + 1]], float(fps[k]))]
