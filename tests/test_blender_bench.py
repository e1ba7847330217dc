"""`python -m shapemove bench keys --quick`: the keyframe writer against a keyframe_insert loop
(the bench itself checks both keyed identical values). Runs in a subprocess (bpy)."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
pytestmark = pytest.mark.blender


def test_keys_bench_reports_a_speedup(tmp_path):
    out = tmp_path / "bench.json"
    proc = subprocess.run([sys.executable, "-m", "shapemove", "bench", "keys", "--quick", "--json", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "keys_speedup" in proc.stdout and "baseline" in proc.stdout
    ratio = json.loads(out.read_text())["keys_speedup"]
    # quick run: 60 frames (~7x here); the full run (400 frames) reaches ~50x, the goal is >= 20x
    assert ratio > 2.0, proc.stdout
