"""Retargeting onto the user's armature inside real Blender (bpy module): Rigify / Mixamo / CC /
unnamed armatures built in the test, in T- and A-poses with random bone rolls, a turned and moved
armature object, an FBX-style one (Y-up centimetre data, object turned and scaled 0.01), mapped
by the "Map Bones" operator and baked by "Bake onto Rig" (keys through the action's channelbag); the world positions of the mapped bones that Blender evaluates are
compared with the source motion's joints, scaled. Also the headless `retarget-rig` command.

The Blender part runs in one subprocess (tests/blender_rig_checks.py)."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rig_builders import planted_motion, wavy_motion, z_up
from shapemove.core.scene.capsule_body import REST_JOINTS
from shapemove.core.scene.motion_file import save_motion

pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
pytestmark = pytest.mark.blender

ROOT = Path(__file__).resolve().parents[1]
MM = 1e-3


def _turned(deg, move, scale):
    a = np.radians(deg)
    M = np.eye(4)
    M[:3, :3] = scale * np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    M[:3, 3] = move
    return M


CASES = [
    dict(name="rigify_A", scheme="rigify", pose="A", scale=1.1, motion="wavy", seed=1),
    dict(name="mixamo_T", scheme="mixamo", pose="T", scale=0.9, motion="wavy", seed=2),
    dict(name="cc_A", scheme="cc", pose="A", scale=1.0, motion="wavy", seed=3, preset="cc_iclone"),
    dict(name="unnamed_A", scheme="unnamed", pose="A", scale=1.2, motion="wavy", seed=4),
    dict(name="mixamo_turned", scheme="mixamo", pose="A", scale=0.5, motion="wavy", seed=5,
         matrix_world=_turned(90, [2.0, -1.0, 0.0], 2.0).tolist()),
    dict(name="fbx_style", scheme="mixamo", pose="A", scale=1.0, motion="wavy", seed=7, data_in_object_space=True,
         matrix_world=[[0.01, 0, 0, 0], [0, 0, -0.01, 0], [0, 0.01, 0, 0], [0, 0, 0, 1]]),
    dict(name="planted", scheme="rigify", pose="A", scale=1.0, motion="planted", seed=6, reproportion=True,
         plant_feet=True),
]


@pytest.fixture(scope="module")
def baked(tmp_path_factory):
    d = tmp_path_factory.mktemp("rig_retarget")
    motions = {"wavy": wavy_motion(REST_JOINTS, 30, seed=1), "planted": planted_motion(REST_JOINTS, 40)}
    paths = {k: str(save_motion(d / f"{k}.npz", m)) for k, m in motions.items()}
    cases = [dict(c) for c in CASES]
    cases[1]["save_blend"] = str(d / "mixamo_in.blend")
    cases[3]["preset_file"] = str(d / "unnamed_map.json")
    cfg = dict(motions=paths, cases=cases, out=str(d / "results.npz"), info=str(d / "info.json"),
               headless=dict(motion=paths["wavy"], blend=str(d / "mixamo_in.blend"), armature="mixamo_T",
                             out=str(d / "headless_out.blend"), plant_feet=False))
    (d / "config.json").write_text(json.dumps(cfg))
    proc = subprocess.run([sys.executable, str(ROOT / "tests" / "blender_rig_checks.py"), str(d / "config.json")],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    res = dict(np.load(d / "results.npz"))
    return dict(motions=motions, paths=paths, res=res, info=json.loads((d / "info.json").read_text()), dir=d)


def _scaled_source(motion, scale, matrix=np.eye(3)):
    return scale * z_up(motion.joints.astype(np.float64)) @ matrix.T


@pytest.mark.parametrize("name,scale", [("rigify_A", 1.1), ("mixamo_T", 0.9), ("cc_A", 1.0), ("unnamed_A", 1.2),
                                        ("fbx_style", 1.0)])
def test_blender_bake_follows_the_scaled_source(baked, name, scale):
    """Every mapped joint within 0.5 mm of the
    source joint x scale, up to one constant vertical offset (floor to floor)."""
    got = baked["res"][name]
    info = baked["info"][name]
    assert len(info["mapping"]) >= 20 and info["frame_end"] == 30 and abs(info["fps"] - 20) < 1e-6
    src = _scaled_source(baked["motions"]["wavy"], scale)
    cols = [i for i in range(22) if not np.isnan(got[0, i, 0])]
    diff = got[:, cols] - src[:, cols]
    offset = diff.reshape(-1, 3).mean(0)
    assert np.abs(offset[:2]).max() < 0.5 * MM
    err = np.abs(diff - offset).max()
    assert err < 0.5 * MM, (name, err)


def test_blender_bone_map_saved_and_loaded_by_the_operators(baked):
    info = baked["info"]["unnamed_A"]
    assert info["reloaded_map"] == info["mapping"] and len(info["mapping"]) == 22
    saved = json.loads((baked["dir"] / "unnamed_map.json").read_text())
    assert saved["format"] == "shapemove-bone-map" and saved["bones"]["left_hip"] == [info["mapping"]["left_hip"]]


def test_blender_bake_on_a_turned_moved_scaled_object(baked):
    got = baked["res"]["mixamo_turned"]
    M = np.asarray(CASES[4]["matrix_world"])
    src = _scaled_source(baked["motions"]["wavy"], 1.0, M[:3, :3] / 2.0)
    cols = [i for i in range(22) if not np.isnan(got[0, i, 0])]
    d = got[:, cols] - src[:, cols]
    assert np.abs(d - d.reshape(-1, 3).mean(0)).max() < 0.5 * MM
    np.testing.assert_allclose(d.reshape(-1, 3).mean(0)[:2], M[:2, 3], atol=0.5 * MM)


def test_blender_feet_planted_on_other_proportions(baked):
    """Rigify-style rig with shorter thighs and longer shins, A-pose: ankles hold within 1 mm while
    the source stands (its pelvis bobbing and turning), at the rig's own ankle height."""
    got = baked["res"]["planted"]
    rest = baked["res"]["planted__rest"]
    slide = np.ptp(got[:, [7, 8]], axis=0).max()
    assert slide < 1 * MM, slide
    np.testing.assert_allclose(got[:, 7, 2], rest[7, 2], atol=2 * MM)
    # the pelvis really moves (the test is not trivially still)
    assert np.ptp(got[:, 0, 2]) > 0.03


def test_blender_headless_bake_of_a_saved_blend(baked):
    info = baked["info"]["headless"]
    assert info["frames"] == 30 and info["mapping"].startswith("22 of 22") and "Mixamo" in info["mapping"]
    np.testing.assert_allclose(baked["res"]["headless"], baked["res"]["mixamo_T"], atol=0.05 * MM)


def test_cli_retarget_rig(baked, tmp_path):
    d = baked["dir"]
    out = tmp_path / "cli.blend"
    cmd = [sys.executable, "-m", "shapemove", "retarget-rig", "--motion", baked["paths"]["wavy"],
           "--blend", str(d / "mixamo_in.blend"), "--armature", "mixamo_T", "--out", str(out), "--preset", "mixamo"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "baked 30 frames onto mixamo_T" in proc.stdout and out.is_file()
    bad = subprocess.run(cmd[:-6] + ["--armature", "Nobody", "--out", str(tmp_path / "x.blend")],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "no armature object 'Nobody'" in bad.stderr and "mixamo_T" in bad.stderr
