"""Hostile archives (issue 11): decompression bombs, path traversal, links, sparse members,
truncated files, a stale cache under the same name, a full disk. Payloads only ever aim at a
marker path in tmp_path; the tests assert it does NOT exist and nothing is left in the cache."""
import io
import os
import shutil
import subprocess
import sys
import tarfile
import zipfile

import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.archive import unpack


class _Zeros(io.RawIOBase):
    def __init__(self, n):
        self.n = n

    def readable(self):
        return True

    def readinto(self, b):
        k = min(len(b), self.n)
        b[:k] = bytes(k)
        self.n -= k
        return k


def _tar(path, members, mode="w:gz"):
    """members: (name, bytes | int (that many zeros), kind='file'|'symlink'|'link', linkname)."""
    with tarfile.open(path, mode, **({"preset": 0} if mode.endswith("xz") else {})) as tf:
        for name, data, *kind in members:
            info = tarfile.TarInfo(name)
            if kind and kind[0] in ("symlink", "link"):
                info.type = tarfile.SYMTYPE if kind[0] == "symlink" else tarfile.LNKTYPE
                info.linkname = kind[1]
                tf.addfile(info)
                continue
            info.size = data if isinstance(data, int) else len(data)
            tf.addfile(info, io.BufferedReader(_Zeros(data)) if isinstance(data, int) else io.BytesIO(data))
    return path


def _leftovers(cache):
    return sorted(p.name for p in cache.iterdir()) if cache.exists() else []


def test_tar_xz_bomb_refused_and_cleaned(tmp_path):
    arc = _tar(tmp_path / "bomb.tar.xz", [("clip.bvh", b"HIERARCHY\n"), ("zeros.bin", 200 << 20)], "w:xz")
    assert arc.stat().st_size < 100_000  # ~30 KB that would write 200 MB
    cache = tmp_path / "cache"
    with pytest.raises(ShapeMoveError, match="decompression bomb"):
        unpack(arc, cache / "bomb")
    assert _leftovers(cache) == []


def test_zip_bomb_refused_before_writing(tmp_path):
    arc = tmp_path / "bomb.zip"
    with zipfile.ZipFile(arc, "w", zipfile.ZIP_DEFLATED) as zf:
        with zf.open("zeros.bin", "w") as fh:
            for _ in range(100):
                fh.write(bytes(1 << 20))
    assert arc.stat().st_size < 200_000
    cache = tmp_path / "cache"
    with pytest.raises(ShapeMoveError, match="decompression bomb"):
        unpack(arc, cache / "bomb")
    assert _leftovers(cache) == []


@pytest.mark.parametrize("member", ["../marker", "a/../../marker", "/ABS/marker"])
def test_path_traversal_refused(tmp_path, member):
    marker = tmp_path / "marker"
    member = member.replace("/ABS", str(tmp_path))
    for arc in (_tar(tmp_path / "t.tar.gz", [("ok.txt", b"x"), (member, b"pwned")]), tmp_path / "t.zip"):
        if arc.suffix == ".zip":
            with zipfile.ZipFile(arc, "w") as zf:
                zf.writestr("ok.txt", b"x")
                zf.writestr(member, b"pwned")
        with pytest.raises(ShapeMoveError, match="unsafe path"):
            unpack(arc, tmp_path / "cache" / arc.name)
        assert not marker.exists()
    assert _leftovers(tmp_path / "cache") == []


@pytest.mark.parametrize("kind", ["symlink", "link"])
def test_links_refused(tmp_path, kind):
    marker = tmp_path / "marker"
    arc = _tar(tmp_path / "l.tar.gz", [("d/link", b"", kind, str(marker)), ("d/link", b"pwned")])
    with pytest.raises(ShapeMoveError, match="is a link"):
        unpack(arc, tmp_path / "cache" / "l")
    assert not marker.exists()


@pytest.mark.skipif(shutil.which("tar") is None, reason="GNU tar is needed to write a sparse member")
def test_sparse_member_refused_without_reading_it(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    with open(src / "sparse.bin", "wb") as fh:
        fh.truncate(1 << 30)  # 1 GB of holes
        fh.write(b"x")
    arc = tmp_path / "sparse.tar.gz"
    subprocess.run(["tar", "-cSzf", str(arc), "-C", str(src), "sparse.bin"], check=True)
    assert arc.stat().st_size < 100_000
    with pytest.raises(ShapeMoveError, match="sparse file|decompression bomb|MB \\(limit"):
        unpack(arc, tmp_path / "cache" / "sparse")
    assert _leftovers(tmp_path / "cache") == []


def test_truncated_and_garbage_archives(tmp_path):
    arc = _tar(tmp_path / "t.tar.xz", [(f"f{i}.txt", os.urandom(20000)) for i in range(10)], "w:xz")
    data = arc.read_bytes()
    for cut in (len(data) // 2, len(data) - 30, 100):
        bad = tmp_path / "cut.tar.xz"
        bad.write_bytes(data[:cut])
        with pytest.raises(ShapeMoveError, match="not a readable, complete tar or zip archive"):
            unpack(bad, tmp_path / "cache" / "cut")
    garbage = tmp_path / "g.tar.gz"
    garbage.write_bytes(os.urandom(5000))
    with pytest.raises(ShapeMoveError, match="not a readable"):
        unpack(garbage, tmp_path / "cache" / "g")
    assert _leftovers(tmp_path / "cache") == []


def test_cache_is_keyed_on_the_archive_not_its_name(tmp_path):
    arc, dest = tmp_path / "data.tar.gz", tmp_path / "cache" / "data"
    _tar(arc, [("clip.txt", b"first")])
    assert (unpack(arc, dest) / "clip.txt").read_bytes() == b"first"
    _tar(arc, [("clip.txt", b"second, longer")])  # same name, other contents (size and mtime differ)
    os.utime(arc, ns=(arc.stat().st_atime_ns, arc.stat().st_mtime_ns + 10**9))
    assert (unpack(arc, dest) / "clip.txt").read_bytes() == b"second, longer"
    other = tmp_path / "elsewhere" / "data.tar.gz"  # another path with the same name
    other.parent.mkdir()
    _tar(other, [("clip.txt", b"third")])
    assert (unpack(other, dest) / "clip.txt").read_bytes() == b"third"
    assert (unpack(other, dest) / "clip.txt").read_bytes() == b"third"  # and now cached


FULL_DISK = r"""
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))  # every file write past 4 KB fails: a full disk
from shapemove.core.errors import ShapeMoveError
from shapemove.core.io.archive import unpack
try:
    unpack(sys.argv[1], sys.argv[2])
except ShapeMoveError as exc:
    print("SENTENCE:", exc)
"""


def test_full_disk_gives_a_sentence_and_leaves_nothing(tmp_path):
    arc = _tar(tmp_path / "a.tar.gz", [("big.bin", os.urandom(20000))])
    out = subprocess.run([sys.executable, "-c", FULL_DISK, str(arc), str(tmp_path / "cache" / "a")],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert "SENTENCE:" in out.stdout and "disk full" in out.stdout, out.stdout
    assert "Traceback" not in out.stderr
    assert _leftovers(tmp_path / "cache") == []
