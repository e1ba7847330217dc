"""Tracebacks where a sentence belongs (issue 11): bad sampling numbers, an output whose parent is a
file, a read-only folder, a full disk (no *.tmp left behind), a pickled Mean.npy, a truncated
archive given to `data build`. Each must end in one `error: ...` line and exit code 2."""
import errno
import os
import subprocess
import sys

import numpy as np
import pytest

from shapemove.cli import main
from shapemove.core.atomic import atomic_path, atomic_save_npy, atomic_write_bytes, atomic_write_json
from shapemove.core.errors import ShapeMoveError


def _run(argv, capsys):
    code = main(argv)
    err = capsys.readouterr().err
    return code, err


@pytest.mark.parametrize("extra, match", [
    (["--temperature", "nan"], "temperature must be a finite number"),
    (["--temperature", "inf"], "temperature must be a finite number"),
    (["--temperature", "-1"], "temperature must be a finite number"),
    (["--top-k", "-5"], "top-k must be 0"),
    (["--seed", "1" + "0" * 30], "seed must be between 0 and 2\\*\\*63-1"),
    (["--seed", "-3"], "seed must be between"),
])
def test_generate_bad_sampling_numbers(tmp_path, capsys, extra, match):
    import re

    code, err = _run(["generate", "--prompt", "a person walks", "--out", str(tmp_path / "m.npz"), *extra], capsys)
    assert code == 2 and err.startswith("error: ") and re.search(match, err), err
    assert "Traceback" not in err and not (tmp_path / "m.npz").exists()


def test_generate_seed_that_is_not_an_integer(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:  # argparse: one usage line, exit 2
        main(["generate", "--prompt", "a person walks", "--seed", "1e30", "--out", str(tmp_path / "m.npz")])
    assert e.value.code == 2 and "invalid int value: '1e30'" in capsys.readouterr().err


def test_generate_output_parent_is_a_file(tmp_path, capsys):
    (tmp_path / "file").write_text("x")
    code, err = _run(["generate", "--prompt", "a person walks", "--out", str(tmp_path / "file" / "m.npz")], capsys)
    assert code == 2 and "is a file, not a folder" in err and "Traceback" not in err


def test_check_sampling_in_the_core():
    from shapemove.core.generation.sampling_params import check_sampling

    assert check_sampling(3, 0.7, 50) == (3, 0.7, 50)
    assert check_sampling(np.int64(4), 1, None) == (4, 1.0, None)
    for bad in [(True, 1.0, 5), (1.5, 1.0, 5), (0, "1", 5), (0, float("nan"), 5), (0, 1.0, -1), (0, 1.0, 2.5)]:
        with pytest.raises(ShapeMoveError):
            check_sampling(*bad)


# -- the atomic writer ------------------------------------------------------------------------
def test_atomic_write_keeps_old_file_and_leaves_no_tmp_on_failure(tmp_path):
    p = tmp_path / "out.json"
    atomic_write_json(p, {"a": 1})
    with pytest.raises(RuntimeError):
        with atomic_path(p) as tmp:
            tmp.write_text("half")
            raise RuntimeError("writer crashed")
    assert p.read_text().strip() == '{\n  "a": 1\n}'
    assert sorted(x.name for x in tmp_path.iterdir()) == ["out.json"]
    with pytest.raises(ValueError):  # object arrays are refused (np.save allow_pickle=False)
        atomic_save_npy(tmp_path / "m.npy", np.array([{"x": 1}], dtype=object))
    assert sorted(x.name for x in tmp_path.iterdir()) == ["out.json"]


def test_json_with_nan_is_written_as_valid_json(tmp_path):
    import json

    res = {"a": float("nan"), "b": [1.5, float("inf"), (float("-inf"), 2)], "c": {"d": np.float64("nan"), "e": "x"}}
    p = atomic_write_json(tmp_path / "r.json", res, nan_to_null=True)
    assert json.loads(p.read_text()) == {"a": None, "b": [1.5, None, [None, 2]], "c": {"d": None, "e": "x"}}
    assert "NaN" in atomic_write_json(tmp_path / "raw.json", res).read_text()  # only when asked


def test_read_only_folder(tmp_path, monkeypatch):
    """Root ignores permission bits, so the read-only file system is simulated at os.replace."""
    real = os.replace

    def erofs(src, dst):
        raise OSError(errno.EROFS, "Read-only file system", str(dst))

    monkeypatch.setattr(os, "replace", erofs)
    with pytest.raises(ShapeMoveError, match="cannot write .*out.bin: the file system is read-only"):
        atomic_write_bytes(tmp_path / "out.bin", b"x" * 100)
    monkeypatch.setattr(os, "replace", real)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_folder_for_real(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        with pytest.raises(ShapeMoveError, match="permission denied"):
            atomic_write_bytes(ro / "out.bin", b"x")
    finally:
        ro.chmod(0o755)


FULL_DISK = r"""
import resource, signal, sys
import numpy as np
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (65536, 65536))  # writes past 64 KB fail, as on a full disk
from shapemove.core.atomic import atomic_save_npy, atomic_write_bytes
from shapemove.core.errors import ShapeMoveError
folder = sys.argv[1]
for write in (lambda: atomic_write_bytes(folder + "/a.bin", b"x" * 200000),
              lambda: atomic_save_npy(folder + "/b.npy", np.zeros(100000))):
    try:
        write()
        print("WROTE")
    except ShapeMoveError as exc:
        print("SENTENCE:", exc)
"""


def test_full_disk_is_a_sentence_and_leaves_no_tmp(tmp_path):
    out = subprocess.run([sys.executable, "-c", FULL_DISK, str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("SENTENCE: cannot write") == 2 and "disk full" in out.stdout, out.stdout
    assert "Traceback" not in out.stderr
    assert list(tmp_path.iterdir()) == []


def test_pickled_mean_npy_is_refused(tmp_path):
    from shapemove.core.train.motion_dataset import load_stats

    marker = tmp_path / "marker"

    class Evil:
        def __reduce__(self):
            return exec, (f"open({str(marker)!r}, 'w').close()",)

    np.save(tmp_path / "Mean.npy", np.array([Evil()], dtype=object), allow_pickle=True)
    np.save(tmp_path / "Std.npy", np.ones(263, np.float32))
    with pytest.raises(ShapeMoveError, match="cannot be read as plain number arrays"):
        load_stats(tmp_path)
    assert not marker.exists()
    (tmp_path / "Mean.npy").write_bytes(b"\x93NUMPY garbage")
    with pytest.raises(ShapeMoveError, match="cannot be read as plain number arrays"):
        load_stats(tmp_path)


def test_data_build_with_truncated_archive(tmp_path, capsys):
    import io
    import tarfile

    arc = tmp_path / "mine.tar.xz"
    with tarfile.open(arc, "w:xz") as tf:
        for i in range(5):
            data = os.urandom(30000)
            info = tarfile.TarInfo(f"mine/clip{i}.bvh")
            info.size = len(data)
            tf.addfile(info, io.BytesIO(data))
    arc.write_bytes(arc.read_bytes()[: arc.stat().st_size // 2])
    env_cache = tmp_path / "cache"
    os.environ["SHAPEMOVE_CACHE"] = str(env_cache)
    try:
        code, err = _run(["data", "build", "--source", str(arc), "--out", str(tmp_path / "built")], capsys)
    finally:
        del os.environ["SHAPEMOVE_CACHE"]
    assert code == 2 and "not a readable, complete tar or zip archive" in err and "Traceback" not in err
