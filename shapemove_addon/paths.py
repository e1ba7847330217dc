"""Where the add-on keeps its files: generated motions, exports and trained models.

Installed as a Blender extension the root is ``bpy.utils.extension_path_user(<extension>)``
(survives upgrades of the extension); run as a plain module (``shapemove.shapemove_addon``,
headless scripts) it is $SHAPEMOVE_HOME, else ``$XDG_DATA_HOME/shapemove`` (~/.local/share/shapemove).
"""
from __future__ import annotations

import os
import re
import sys
import time
from pathlib import Path

import bpy

from ..core.errors import ShapeMoveError
from ..core.worker.client import torch_importable
from .preferences import ADDON_ID, preferences

HOME_ENV_VAR = "SHAPEMOVE_HOME"
PACKAGE_ROOT = Path(__file__).resolve().parents[1]


def user_dir() -> Path:
    """The add-on's writable folder (created)."""
    root = ""
    if ADDON_ID.startswith("bl_ext."):
        try:
            root = bpy.utils.extension_path_user(ADDON_ID, create=True)
        except (ValueError, OSError):
            root = ""
    if not root:
        root = os.environ.get(HOME_ENV_VAR) or os.path.join(
            os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share"), "shapemove")
    path = Path(root)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ShapeMoveError(f"cannot create the ShapeMove folder {path}: {exc}") from None
    return path


def _sub(*parts) -> Path:
    path = user_dir().joinpath(*parts)
    path.mkdir(parents=True, exist_ok=True)
    return path


def data_dir() -> Path:
    """Generated and retargeted motions, re-decoded variants, temporary BVH exports."""
    return _sub("data")


def models_dir(context=None) -> Path:
    """The preferences' models folder, else ``<user dir>/models`` (created)."""
    prefs = preferences(context)
    custom = bpy.path.abspath(prefs.models_dir) if prefs is not None and prefs.models_dir else ""
    if custom:
        path = Path(custom)
        path.mkdir(parents=True, exist_ok=True)
        return path
    return _sub("models")


def slug(text: str, limit: int = 40) -> str:
    """A file-name-safe short form of ``text`` ("a person waves!" -> "a_person_waves")."""
    s = re.sub(r"[^A-Za-z0-9]+", "_", str(text)).strip("_").lower()
    return s[:limit].rstrip("_") or "motion"


def new_motion_path(label: str, folder: Path | None = None) -> Path:
    """A fresh ``.npz`` path under the data folder, named after ``label`` and the time."""
    folder = Path(folder) if folder is not None else data_dir()
    stem = f"{time.strftime('%Y%m%d-%H%M%S')}_{slug(label)}"
    path = folder / f"{stem}.npz"
    n = 1
    while path.exists():
        n += 1
        path = folder / f"{stem}_{n}.npz"
    return path


def _has_torch(python: Path) -> bool:
    import subprocess

    try:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONHOME"}
        return subprocess.run([str(python), "-c", "import torch"], capture_output=True, timeout=60, env=env).returncode == 0
    except (OSError, subprocess.SubprocessError):
        return False


def candidate_pythons() -> list[Path]:
    """Python executables a worker could use, most likely first: $SHAPEMOVE_PYTHON, a ``.venv``
    beside the package (developer checkout) or in the user folder, $VIRTUAL_ENV, $CONDA_PREFIX."""
    out: list[Path] = []
    env = [os.environ.get("SHAPEMOVE_PYTHON"), os.environ.get("VIRTUAL_ENV"), os.environ.get("CONDA_PREFIX")]
    roots = [PACKAGE_ROOT / ".venv", PACKAGE_ROOT.parent / ".venv", user_dir() / "venv", *[e for e in env if e]]
    for root in roots:
        p = Path(root)
        for exe in (p, p / "bin" / "python3", p / "bin" / "python", p / "Scripts" / "python.exe", p / "python.exe"):
            if exe.is_file() and exe not in out:
                out.append(exe)
                break
    return out


def detect_python() -> str:
    """"" when torch imports in this Python (jobs run in-process), else the first candidate
    Python where it imports; ShapeMoveError asking the user to set one when none works."""
    if torch_importable():
        return ""
    for exe in candidate_pythons():
        if Path(exe).resolve() != Path(sys.executable).resolve() and _has_torch(exe):
            return str(exe)
    raise ShapeMoveError("no Python with PyTorch found: install ShapeMove's requirements into a virtual "
                         "environment and set it as 'Python environment' in the ShapeMove preferences")
