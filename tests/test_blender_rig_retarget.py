"""Retargeting onto the user's armature inside real Blender (bpy module): Rigify / Mixamo / CC /
unnamed armatures, T- and A-poses, a turned and moved object, an FBX-style one, mapped and baked
by the add-on's operators and by the headless function; then the `retarget-rig` command.

The Blender tests are pytest tests in tests/in_blender/test_rig_retarget.py, run in their own
process; each is reported here as ``test_in_blender[name]`` with its own assertion message.
"""
from __future__ import annotations

import subprocess
import sys

import blender_inside
import pytest
from conftest import need_module

need_module("bpy", "needs the bpy module (pip install bpy==5.0.1)")
pytestmark = pytest.mark.blender


@pytest.fixture(scope="module")
def baked(tmp_path_factory):
    d = tmp_path_factory.mktemp("rig_retarget")
    results = blender_inside.run("test_rig_retarget.py", dict(dir=str(d), user_resources=str(d / "user")), d)
    return dict(results=results, dir=d)


@pytest.mark.parametrize("name", blender_inside.inner_tests("test_rig_retarget.py"))
def test_in_blender(baked, name):
    """One test of tests/in_blender/test_rig_retarget.py, run inside Blender (see its docstring)."""
    blender_inside.check(baked["results"], name)


def test_cli_retarget_rig(baked, tmp_path):
    d = baked["dir"]
    out = tmp_path / "cli.blend"
    cmd = [sys.executable, "-m", "shapemove", "retarget-rig", "--motion", str(d / "wavy.npz"),
           "--blend", str(d / "mixamo_in.blend"), "--armature", "mixamo_T", "--out", str(out), "--preset", "mixamo"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "baked 30 frames onto mixamo_T" in proc.stdout and out.is_file()
    bad = subprocess.run(cmd[:-6] + ["--armature", "Nobody", "--out", str(tmp_path / "x.blend")],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "no armature object 'Nobody'" in bad.stderr and "mixamo_T" in bad.stderr
