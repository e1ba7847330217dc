"""Locate the shared motion-capture archives and unpack them once into a cache folder.

The archives (``bandai.tar.xz``, ``hdm05.tar.xz``, ``cmu.tar.xz``) are never committed; they are
unpacked into an ignored cache so tests and the dataset builder read plain files.
"""
from __future__ import annotations

import lzma
import os
import shutil
import tarfile
import zipfile
import zlib
from pathlib import Path

from ..errors import ShapeMoveError

REPO_ROOT = Path(__file__).resolve().parents[2]
ARCHIVES = ("bandai", "hdm05", "cmu", "cmu_extra", "deepmimic")


def default_data_dir() -> Path:
    """``$SHAPEMOVE_DATA`` or ``../shared/data`` beside the repository."""
    env = os.environ.get("SHAPEMOVE_DATA")
    return Path(env) if env else REPO_ROOT.parent / "shared" / "data"


def default_cache_dir() -> Path:
    env = os.environ.get("SHAPEMOVE_CACHE")
    return Path(env) if env else REPO_ROOT / ".cache"


# Archives are untrusted: every member is checked (path, type, size) before anything is written,
# bytes are streamed in chunks and counted, and the total is capped relative to the archive size
# (the shared archives unpack to at most 8x their size; a bomb unpacks to thousands).
MAX_MEMBERS = 200_000
MAX_MEMBER_BYTES = 1 << 30
MAX_TOTAL_BYTES = 16 << 30
MAX_RATIO = 50  # extracted bytes per archive byte, above a 64 MB allowance
RATIO_FLOOR = 64 << 20
_CHUNK = 1 << 20


def cache_key(archive: Path) -> str:
    """What the unpacked cache is valid for: the archive's resolved path, size and mtime."""
    st = archive.stat()
    return f"{archive.resolve()}|{st.st_size}|{st.st_mtime_ns}"


def _cache_valid(archive: Path, marker: Path) -> bool:
    if not marker.is_file():
        return False
    try:
        text = marker.read_text()
        if not archive.is_file():
            return True  # the archive is gone: the unpacked copy is all there is
        if text == cache_key(archive):
            return True
        # written by an older version (the path only): valid if unpacked after the archive last changed
        if text == str(archive) and marker.stat().st_mtime_ns >= archive.stat().st_mtime_ns:
            from ..atomic import atomic_write_text

            atomic_write_text(marker, cache_key(archive))
            return True
    except OSError:
        return False
    return False


def _safe_name(archive: Path, name: str) -> Path:
    parts = Path(name).parts
    if not name or name.startswith(("/", "\\")) or ".." in parts or (parts and ":" in parts[0]):
        raise ShapeMoveError(f"{archive}: unsafe path in archive: {name[:200]!r}")
    return Path(*parts) if parts else Path(".")


class _Budget:
    def __init__(self, archive: Path):
        self.archive = archive
        self.limit = min(MAX_TOTAL_BYTES, max(RATIO_FLOOR, MAX_RATIO * archive.stat().st_size))
        self.used = 0
        self.members = 0

    def member(self, name: str, size: int) -> None:
        self.members += 1
        if self.members > MAX_MEMBERS:
            raise ShapeMoveError(f"{self.archive}: more than {MAX_MEMBERS:,} files in the archive; refused")
        if size > MAX_MEMBER_BYTES:
            raise ShapeMoveError(f"{self.archive}: member {name[:200]!r} is {size / 2**20:,.0f} MB (limit "
                                 f"{MAX_MEMBER_BYTES >> 20} MB); refused")

    def take(self, n: int, name: str) -> None:
        self.used += n
        if self.used > self.limit:
            raise ShapeMoveError(f"{self.archive}: unpacks to more than {self.limit / 2**20:,.0f} MB "
                                 f"({MAX_RATIO}x its size); refused as a decompression bomb (at {name[:200]!r})")


def _copy(src, dst: Path, budget: _Budget, name: str, declared: int) -> None:
    """Stream a member to ``dst`` in chunks, counting bytes against the budget (never whole)."""
    written = 0
    with open(dst, "wb") as out:
        while chunk := src.read(_CHUNK):
            written += len(chunk)
            if written > declared:
                raise ShapeMoveError(f"{budget.archive}: member {name[:200]!r} holds more than its declared size")
            budget.take(len(chunk), name)
            out.write(chunk)


def _extract_zip(archive: Path, tmp: Path, budget: _Budget) -> None:
    with zipfile.ZipFile(archive) as zf:
        infos = zf.infolist()
        for info in infos:  # check everything before writing anything
            _safe_name(archive, info.filename)
            budget.member(info.filename, info.file_size)
        if sum(i.file_size for i in infos) > budget.limit:
            budget.take(sum(i.file_size for i in infos), "(declared sizes)")
        budget.members = 0
        for info in infos:
            rel = _safe_name(archive, info.filename)
            target = tmp / rel
            if info.is_dir():
                target.mkdir(parents=True, exist_ok=True)
                continue
            target.parent.mkdir(parents=True, exist_ok=True)
            with zf.open(info) as src:
                _copy(src, target, budget, info.filename, info.file_size)


def _extract_tar(archive: Path, tmp: Path, budget: _Budget) -> None:
    with tarfile.open(archive) as tf:  # streamed: members are checked as they come
        for info in iter(tf.next, None):
            rel = _safe_name(archive, info.name)
            budget.member(info.name, info.size)
            target = tmp / rel
            if info.isdir():
                target.mkdir(parents=True, exist_ok=True)
            elif info.isreg() and not info.issparse():
                target.parent.mkdir(parents=True, exist_ok=True)
                src = tf.extractfile(info)
                _copy(src, target, budget, info.name, info.size)
            elif info.issym() or info.islnk() or info.issparse():
                raise ShapeMoveError(f"{archive}: member {info.name[:200]!r} is a "
                                     f"{'sparse file' if info.issparse() else 'link'}; only plain files are unpacked")
            else:
                raise ShapeMoveError(f"{archive}: member {info.name[:200]!r} is a device or FIFO; refused")
        # read the compressed stream to its end: a truncated .tar.xz/.tar.gz fails here (EOFError) even
        # when the tar's own end marker came before the cut
        while chunk := tf.fileobj.read(_CHUNK):
            budget.take(len(chunk), "(data after the last member)")


def unpack(archive: Path, dest: Path) -> Path:
    """Unpack a ``.tar.xz``/``.tar.gz``/``.tar``/``.zip`` into ``dest`` once (atomic: a temp folder
    renamed into place, so an interrupted unpack is redone, never half-used). The cache is valid
    for the archive's path, size and mtime (``cache_key``): another archive with the same name is
    unpacked again. Bounded: member count, member size and total bytes (see the limits above);
    links, devices and sparse members are refused. Returns ``dest``."""
    archive = Path(archive)
    dest = Path(dest)
    if _cache_valid(archive, dest / ".unpacked"):
        return dest
    if not archive.is_file():
        raise ShapeMoveError(f"archive not found: {archive}")
    tmp = dest.with_name(f"{dest.name}.{os.getpid()}.partial")
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        tmp.mkdir(parents=True)
        budget = _Budget(archive)
        if zipfile.is_zipfile(archive):
            _extract_zip(archive, tmp, budget)
        else:
            _extract_tar(archive, tmp, budget)
        (tmp / ".unpacked").write_text(cache_key(archive))
        shutil.rmtree(dest, ignore_errors=True)
        try:
            os.replace(tmp, dest)
        except OSError:
            if not _cache_valid(archive, dest / ".unpacked"):  # another process unpacked it meanwhile: use that
                raise
    except ShapeMoveError:
        raise
    except (tarfile.TarError, zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, ValueError, lzma.LZMAError,
            zlib.error) as exc:
        # truncated (EOFError), corrupt (lzma/zlib errors are ValueError/OSError subclasses), not an archive
        raise ShapeMoveError(f"{archive}: not a readable, complete tar or zip archive "
                             f"({type(exc).__name__}: {exc})") from None
    except OSError as exc:
        from ..atomic import os_error_sentence

        what = "unpack" if exc.filename is None or str(tmp) in str(exc.filename) else "read"
        raise ShapeMoveError(f"{os_error_sentence(exc, archive, what)} (into {dest})") from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return dest


def mocap_root(data_dir: Path | None = None, cache_dir: Path | None = None) -> Path:
    """Folder holding ``bandai/``, ``hdm05/``, ``cmu/``, ``cmu_extra/`` and ``deepmimic/`` unpacked
    from the shared archives.

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
        inner = target / name if (target / name).is_dir() else target / "cmu"  # cmu_extra holds cmu/
        if not link.exists():
            link.symlink_to(inner, target_is_directory=True)
    return root
