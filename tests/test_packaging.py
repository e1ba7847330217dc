"""Packaging: Blender's own validator accepts the manifest and the zip, the zip leaves out data and
dev files, the licences are where they belong, and the wheel (built from pyproject.toml alone)
holds the default model, its configs and the body model."""
from __future__ import annotations

import importlib.util
import re
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MANIFEST = tomllib.loads((ROOT / "blender_manifest.toml").read_text())
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())


def _builder():
    spec = importlib.util.spec_from_file_location("build_extension", ROOT / "tools" / "build_extension.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _blender_ext() -> Path:
    spec = importlib.util.find_spec("bpy")  # located, not imported
    if spec is None or not spec.submodule_search_locations:
        pytest.skip("needs the bpy module (pip install bpy==5.0.1) for Blender's blender_ext.py")
    hits = sorted(Path(list(spec.submodule_search_locations)[0]).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
    assert hits, "the bpy module has no bundled blender_ext.py"
    return hits[-1]


def _validate(path: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(_blender_ext()), "validate", str(path)],
                          capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def extension_zip(tmp_path_factory) -> Path:
    return _builder().build(tmp_path_factory.mktemp("dist"))


def test_blender_validator_accepts_the_manifest_and_the_zip(extension_zip):
    for path in (ROOT, extension_zip):
        proc = _validate(path)
        assert proc.returncode == 0 and "Success" in proc.stdout, (path, proc.stdout + proc.stderr)
    assert len(MANIFEST["permissions"]["files"]) <= 64  # the limit the validator enforces


def test_blender_validator_rejects_a_broken_manifest(tmp_path):
    # the validator really checks: the old 85-character permission text fails
    text = (ROOT / "blender_manifest.toml").read_text()
    bad = re.sub(r'files = ".*"', 'files = "' + "x" * 85 + '"', text)
    assert bad != text
    (tmp_path / "blender_manifest.toml").write_text(bad)
    (tmp_path / "__init__.py").write_text("")
    proc = _validate(tmp_path)
    assert proc.returncode != 0 and "64 characters" in proc.stdout + proc.stderr


def test_zip_ships_the_addon_and_licences_but_no_dev_files(extension_zip):
    names = zipfile.ZipFile(extension_zip).namelist()
    tops = {n.split("/", 1)[0] for n in names}
    assert {"blender_manifest.toml", "__init__.py", "LICENSE", "core", "shapemove_addon", "weights", "assets",
            "configs"} <= tops
    assert not tops & {"tests", "tools", "bench", "data", "docs", ".ci", ".git", ".venv", ".cache", "Makefile",
                       "pyproject.toml", "DEVELOPERS.md", ".gitignore", "dist", "runs", "out", "build"}
    assert "weights/default/LICENSE.txt" in names and "assets/OPENBODY_LICENSE.txt" in names
    assert not [n for n in names if "__pycache__" in n or n.endswith((".pyc", ".tmp")) or ".egg-info" in n]


def test_zip_leaves_out_a_data_folder_built_in_the_root(tmp_path):
    # a scratch extension root with what a developer's checkout has lying around
    for rel, text in {"blender_manifest.toml": (ROOT / "blender_manifest.toml").read_text(), "__init__.py": "",
                      "core/a.py": "", "data/built/clips.npz": "x", "data/raw.bvh": "x", "tools/t.py": "",
                      "tests/test_x.py": "", "docs/ARCHITECTURE.md": "", "core/b.py.tmp": "",
                      "core/__pycache__/a.cpython-311.pyc": "", "LICENSE": "GPL"}.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    out = _builder().build(tmp_path / "dist", root=tmp_path)
    assert sorted(zipfile.ZipFile(out).namelist()) == ["LICENSE", "__init__.py", "blender_manifest.toml", "core/a.py"]


def test_licences():
    gpl = (ROOT / "LICENSE").read_text()
    assert "GNU GENERAL PUBLIC LICENSE" in gpl and "Version 3, 29 June 2007" in gpl
    assert "END OF TERMS AND CONDITIONS" in gpl and "How to Apply These Terms to Your New Programs" in gpl
    assert len(gpl) > 30000  # the full text, not a notice
    assert MANIFEST["license"] == ["SPDX:GPL-3.0-or-later"] and PYPROJECT["project"]["license"] == "GPL-3.0-or-later"
    weights = (ROOT / "weights" / "default" / "LICENSE.txt").read_text()
    for needed in ("CC BY-NC 4.0", "NON-COMMERCIAL", "Bandai Namco Research Inc.", "HDM05", "mocap.cs.cmu.edu",
                   "NSF EIA-0196217", "KIT Motion-Language Dataset", "DeepMimic", "MIT License",
                   "Copyright (c) 2018 Xue Bin Peng"):
        assert needed in weights, needed


def test_version_is_written_once():
    import shapemove

    assert not (ROOT / "setup.py").exists()
    assert "version" not in PYPROJECT["project"] and "version" in PYPROJECT["project"]["dynamic"]
    assert shapemove.__version__ == MANIFEST["version"]
    assert 'version = "' not in (ROOT / "__init__.py").read_text()


def test_pyproject_lists_every_package():
    found = {"shapemove"} | {
        "shapemove." + ".".join(p.parent.relative_to(ROOT).parts)
        for p in ROOT.rglob("__init__.py")
        if p.parent != ROOT and not {"tests", "tools", ".venv", ".cache", "build", "dist", ".git"} & set(p.relative_to(ROOT).parts)}
    assert sorted(PYPROJECT["tool"]["setuptools"]["packages"]) == sorted(found), "add the new package to pyproject.toml"


@pytest.mark.slow
def test_wheel_holds_the_default_model_and_configs(tmp_path):
    # built from a copy of the tree, so no build/ folder is left in the checkout
    src = tmp_path / "src"
    top = {".git", ".venv", ".cache", "data", "build", "dist", "out", "runs", ".pytest_cache"}

    def ignore(folder, names):
        return [n for n in names if (Path(folder) == ROOT and n in top) or n == "__pycache__" or n.endswith(".egg-info")]

    shutil.copytree(ROOT, src, ignore=ignore)
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
                           "-w", str(tmp_path), str(src)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    wheels = list(tmp_path.glob("shapemove-*.whl"))
    assert [w.name for w in wheels] == [f"shapemove-{MANIFEST['version']}-py3-none-any.whl"]
    names = set(zipfile.ZipFile(wheels[0]).namelist())
    shipped = {"shapemove/" + p.relative_to(ROOT).as_posix() for d in ("weights/default", "configs", "assets")
               for p in (ROOT / d).rglob("*") if p.is_file() and "__pycache__" not in p.parts}
    assert "shapemove/weights/default/savae.pt" in shipped and "shapemove/weights/default/t5/model.safetensors" in shipped
    assert shipped <= names, sorted(shipped - names)
    assert {"shapemove/__init__.py", "shapemove/blender_manifest.toml", "shapemove/LICENSE",
            "shapemove/core/generation/generate.py", "shapemove/shapemove_addon/panels.py",
            "shapemove/cli/__init__.py"} <= names
    assert not [n for n in names if n.startswith(("shapemove/tests/", "shapemove/tools/", "shapemove/data/"))
                or n.endswith((".pyc", ".tmp"))]
    meta = zipfile.ZipFile(wheels[0]).read(f"shapemove-{MANIFEST['version']}.dist-info/METADATA").decode()
    assert f"Version: {MANIFEST['version']}" in meta
