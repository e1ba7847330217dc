"""The extension inside real Blender (bpy module): install the zip, build rigs with the operator,
check the scene, the forward kinematics, the skinning, shape changes, failure clean-up, a
headless Workbench render, the `blend` command and the MP4 of a saved scene.

The tests themselves are pytest tests in tests/in_blender/test_addon.py, run in their own
process (BLENDER_USER_RESOURCES has to point at a temporary folder before bpy is imported); each
is reported here as ``test_in_blender[name]`` with its own assertion message.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path

import blender_inside
import numpy as np
import pytest
from conftest import need_module

from shapemove.core.body.skeleton import PARENTS
from shapemove.core.scene.capsule_body import capsule_body
from shapemove.core.scene.motion_file import make_motion, save_motion

need_module("bpy", "needs the bpy module (pip install bpy==5.0.1)")
pytestmark = pytest.mark.blender

ROOT = Path(__file__).resolve().parents[1]
FRAMES = 40


def _wavy_motion(body, frames, betas, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(frames)[:, None, None]
    poses = rng.normal(0, 0.4, (1, 24, 3)) * np.sin(0.2 * t + rng.uniform(0, 6, (1, 24, 3)))
    step = np.arange(frames)
    transl = np.stack([0.01 * step, 0.02 * np.sin(0.3 * step), 0.04 * step], -1)  # walks towards +Z (the front)
    return make_motion(body, poses, transl, betas, fps=20, prompt="a test motion")


def _smpl_format_file(body, path) -> str:
    """``body`` written as an SMPL model file (the keys of the official .npz): the extension
    loads a test body the way it loads a user's SMPL file, there is no test body by name."""
    np.savez(path, v_template=body.v_template.numpy(), shapedirs=body.shapedirs.numpy(),
             J_regressor=body.j_regressor.numpy(), weights=body.skin_weights, f=body.faces,
             kintree_table=np.stack([np.where(PARENTS < 0, 2 ** 32 - 1, PARENTS), np.arange(len(PARENTS))]))
    return str(path)


@pytest.fixture(scope="module")
def blender(tmp_path_factory, openbody):
    d = tmp_path_factory.mktemp("blender")
    spec = importlib.util.spec_from_file_location("build_extension", ROOT / "tools" / "build_extension.py")
    builder = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(builder)
    capsule = capsule_body()
    capsule_model = _smpl_format_file(capsule, d / "capsule_neutral.npz")  # loads as "smpl-neutral"
    motion = _wavy_motion(capsule, FRAMES, np.array([0.5, 0, 0, 0, 0, 0, 0, 0, 0, 0.3]))
    motion.body_model = "smpl-neutral"
    save_motion(d / "capsule.npz", motion)
    ob_motion = _wavy_motion(openbody, 12, np.random.default_rng(1).normal(0, 1, 10), seed=2)
    save_motion(d / "openbody.npz", ob_motion)
    motion.body_model = "mystery-body"
    save_motion(d / "bad.npz", motion)
    (d / "render").mkdir()
    config = dict(zip=str(builder.build(d / "dist")), motion=str(d / "capsule.npz"), bad_motion=str(d / "bad.npz"),
                  capsule_model=capsule_model, openbody_motion=str(d / "openbody.npz"), frames=FRAMES,
                  user_resources=str(d / "user"), render_dir=str(d / "render"), cli_blend=str(d / "cli" / "s.blend"))
    return blender_inside.run("test_addon.py", config, d)


@pytest.mark.parametrize("name", blender_inside.inner_tests("test_addon.py"))
def test_in_blender(blender, name):
    """One test of tests/in_blender/test_addon.py, run inside Blender (see its docstring)."""
    blender_inside.check(blender, name)
