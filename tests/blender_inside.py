"""Run a pytest module of tests/in_blender/ in a fresh Python and report each of its tests.

Blender tests need their own process (BLENDER_USER_RESOURCES must be set before bpy is imported,
and a test of registration must see a Python where torch was never imported), but their checks
should still be pytest assertions: the inner run writes a JUnit XML, and the outer test module
turns every inner test into one outer test that passes or fails with the inner failure text.

    results = run("test_addon.py", config, tmp_dir)         # {test name: None | failure text}
    @pytest.mark.parametrize("name", inner_tests("test_addon.py"))
"""
from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

INNER = Path(__file__).resolve().parent / "in_blender"


def inner_tests(test_file: str) -> list[str]:
    """The test functions of ``in_blender/<test_file>``, in file order."""
    tree = ast.parse((INNER / test_file).read_text(encoding="utf-8"))
    return [n.name for n in tree.body if isinstance(n, ast.FunctionDef) and n.name.startswith("test_")]


def run(test_file: str, config: dict, workdir: Path, timeout: int = 600) -> dict:
    """Run the inner module with ``config`` (as $SHAPEMOVE_BLENDER_CONFIG) -> {test name: None when
    it passed, else the failure (or skip/error) text}."""
    workdir = Path(workdir)
    (workdir / "config.json").write_text(json.dumps(config))
    xml = workdir / "results.xml"
    cmd = [sys.executable, "-m", "pytest", str(INNER / test_file), "-q", "-p", "no:cacheprovider",
           "--confcutdir", str(INNER), f"--junitxml={xml}", "-o", "addopts="]
    env = {**os.environ, "SHAPEMOVE_BLENDER_CONFIG": str(workdir / "config.json")}
    proc = subprocess.run(cmd, cwd=INNER.parents[1], env=env, capture_output=True, text=True, timeout=timeout)
    if not xml.exists():
        pytest.fail(f"in-Blender tests did not run ({proc.returncode}):\n{(proc.stdout + proc.stderr)[-4000:]}")
    print(proc.stdout[-2000:])
    out: dict = {}
    for case in ET.parse(xml).getroot().iter("testcase"):
        bad = [e for e in case if e.tag in ("failure", "error", "skipped")]
        out[case.get("name")] = None if not bad else "\n".join(
            f"[{e.tag}] {e.get('message', '')}\n{e.text or ''}" for e in bad)
    return out


def check(results: dict, name: str) -> None:
    """Fail the outer test with the inner one's failure text (or because it did not run)."""
    if name not in results:
        pytest.fail(f"{name} did not run inside Blender", pytrace=False)
    if results[name] is not None:
        pytest.fail(results[name], pytrace=False)
