"""Locate the shared motion-capture archives and unpack them once into a cache folder.

The archives (``bandai.tar.xz``, ``hdm05.tar.xz``, ``cmu.tar.xz``) are never committed; they are
unpacked into an ignored cache so tests and the dataset builder read plain files.
"""
from __future__ import annotations

import os
import shutil
import tarfile
import zipfile
from pathlib import Path

from ..errors import ShapeMoveError

REPO_ROOT = Path(__file__).resolve().parents[2]
ARCHIVES = ("bandai", "hdm05", "cmu")


def default_data_dir() -> Path:
    """``$SHAPEMOVE_DATA`` or ``../shared/data`` beside the repository."""
    env = os.environ.get("SHAPEMOVE_DATA")
    return Path(env) if env else REPO_ROOT.parent / "shared" / "data"


def default_cache_dir() -> Path:
    env = os.environ.get("SHAPEMOVE_CACHE")
    return Path(env) if env else REPO_ROOT / ".cache"


def unpack(archive: Path, dest: Path) -> Path:
    """Unpack a ``.tar.xz``/``.tar.gz``/``.tar``/``.zip`` into ``dest`` once (atomic: a temp folder
    renamed into place, so an interrupted unpack is redone, never half-used). Returns ``dest``."""
    archive = Path(archive)
    dest = Path(dest)
    marker = dest / ".unpacked"
    if marker.exists():
        return dest
    if not archive.is_file():
        raise ShapeMoveError(f"archive not found: {archive}")
    tmp = dest.with_name(dest.name + ".partial")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    try:
        if zipfile.is_zipfile(archive):
            with zipfile.ZipFile(archive) as zf:
                for member in zf.namelist():
                    if member.startswith("/") or ".." in Path(member).parts:
                        raise ShapeMoveError(f"{archive}: unsafe path in archive: {member}")
                zf.extractall(tmp)
        else:
            try:
                with tarfile.open(archive) as tf:
                    tf.extractall(tmp, filter="data")
            except tarfile.TarError as exc:
                raise ShapeMoveError(f"{archive}: not a readable tar or zip archive ({exc})") from exc
        (tmp / ".unpacked").write_text(str(archive))
        shutil.rmtree(dest, ignore_errors=True)
        tmp.rename(dest)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return dest


def mocap_root(data_dir: Path | None = None, cache_dir: Path | None = None) -> Path:
    """Folder holding ``bandai/``, ``hdm05/`` and ``cmu/`` unpacked from the shared archives.

    Raises ShapeMoveError naming the missing archive when one is absent."""
    data_dir = Path(data_dir) if data_dir else default_data_dir()
    cache_dir = Path(cache_dir) if cache_dir else default_cache_dir()
    root = cache_dir / "mocap"
    root.mkdir(parents=True, exist_ok=True)
    for name in ARCHIVES:
        archive = data_dir / f"{name}.tar.xz"
        target = root / f"_{name}"
        if not (target / ".unpacked").exists() and not archive.exists():
            raise ShapeMoveError(f"motion-capture archive missing: {archive} (set SHAPEMOVE_DATA to the folder holding it)")
        unpack(archive, target)
        link = root / name
        if not link.exists():
            link.symlink_to(target / name, target_is_directory=True)
    return root
