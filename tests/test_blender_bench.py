"""`python -m shapemove bench keys --quick` runs, and the keyframe writer it times keys exactly what
a ``keyframe_insert`` loop keys (the bench compares the two key by key and fails otherwise). The
speed ratio is the bench's to report (docs/evaluation.md, Benchmarks), not a test's to assert: timings depend
on the machine. Runs in a subprocess (bpy)."""
from __future__ import annotations

import json
import math
import re
import subprocess
import sys

import pytest
from conftest import need_module

need_module("bpy", "needs the bpy module (pip install bpy==5.0.1)")
pytestmark = pytest.mark.blender


def test_keys_bench_writer_keys_what_keyframe_insert_keys(tmp_path):
    out = tmp_path / "bench.json"
    proc = subprocess.run([sys.executable, "-m", "shapemove", "bench", "keys", "--quick", "--json", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    diff = re.search(r"same keys, max \|difference\| ([0-9.e+-]+)", proc.stdout)
    assert diff is not None and float(diff.group(1)) <= 1e-5, proc.stdout
    assert "60 frames x 24 bones" in proc.stdout
    ratio = json.loads(out.read_text())["keys_speedup"]
    assert math.isfinite(ratio) and ratio > 0
