"""One size bound before and while reading a user's file (core/io/limits.py): FIFOs, /proc files and
files that grow are refused past the limit; every reader words the refusal the same way; a built
dataset's meta is read by one definition (core/data/built_meta.py)."""
import json
import os
import threading
from pathlib import Path

import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.io import limits


def _sparse(path: Path, size: int) -> Path:
    with open(path, "wb") as fh:
        fh.truncate(size)
    return path


class _FifoWriter:
    """A FIFO at ``path`` fed ``data`` by a thread (the reader decides how much it takes)."""

    def __init__(self, path: Path, data: bytes):
        os.mkfifo(path)
        self.path, self.data, self.written = path, data, 0
        self.thread = threading.Thread(target=self._write, daemon=True)
        self.thread.start()

    def _write(self):
        try:
            with open(self.path, "wb") as fh:
                for i in range(0, len(self.data), 4096):
                    fh.write(self.data[i:i + 4096])
                    fh.flush()
                    self.written = i + 4096
        except BrokenPipeError:  # the reader stopped reading: what the bound is for
            pass

    def close(self):
        self.thread.join(5)
        if self.thread.is_alive():  # the reader never opened it: release the writer
            os.close(os.open(self.path, os.O_RDONLY | os.O_NONBLOCK))
            self.thread.join(5)


needs_fifo = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs (os.mkfifo) on this platform")


@needs_fifo
def test_read_json_reads_at_most_its_limit_from_a_fifo(tmp_path):
    big = json.dumps(list(range(200_000))).encode()  # ~1.3 MB of valid JSON; its stat size is 0
    w = _FifoWriter(tmp_path / "big.json", big)
    try:
        assert (tmp_path / "big.json").stat().st_size == 0
        with pytest.raises(ShapeMoveError, match=r"big.json: the preset file is more than 1 MB \(it grew while "
                                                 r"being read, or is not a regular file\); preset files larger "
                                                 r"than 1 MB are refused"):
            limits.read_json(tmp_path / "big.json", "preset")
    finally:
        w.close()
    assert w.written < len(big)  # the writer was cut off: the rest was never read
    small = _FifoWriter(tmp_path / "small.json", b'{"a": [1, 2]}')
    try:
        assert limits.read_json(tmp_path / "small.json", "preset") == {"a": [1, 2]}
    finally:
        small.close()


def test_read_json_refuses_a_file_that_grows_after_its_size_check(tmp_path, monkeypatch):
    f = tmp_path / "grows.json"
    f.write_text("[" + "1, " * 100 + "1]")  # 303 bytes: under the 1,000-byte limit when checked
    real = limits.check_file_size

    def check_then_grow(path, *args, **kwargs):
        size = real(path, *args, **kwargs)
        with open(path, "a") as fh:  # another process appends between the check and the read
            fh.write(" " * 5000)
        return size

    monkeypatch.setattr(limits, "check_file_size", check_then_grow)
    with pytest.raises(ShapeMoveError, match="grows.json: the config file is more than 1,000 bytes"):
        limits.read_json(f, "config", 1000)
    monkeypatch.undo()
    with pytest.raises(ShapeMoveError, match=r"the config file is 5,303 bytes; config files larger than 1,000 bytes"):
        limits.read_json(f, "config", 1000)
    f.write_text("[" + "1, " * 100 + "1]")
    assert limits.read_json(f, "config", 1000) == [1] * 101


@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="no /proc file system")
def test_a_file_whose_size_says_zero_is_still_bounded():
    assert Path("/proc/self/status").stat().st_size == 0  # it holds ~1 KB
    with pytest.raises(ShapeMoveError, match="status file is more than 100 bytes"):
        limits.read_bounded("/proc/self/status", 100, "status")
    assert b"Name:" in limits.read_bounded("/proc/self/status", 1 << 20, "status")


def test_read_json_errors_are_sentences(tmp_path):
    with pytest.raises(ShapeMoveError, match="preset not found"):
        limits.read_json(tmp_path / "none.json", "preset")
    with pytest.raises(ShapeMoveError, match="cannot read preset .*: it is a folder"):
        limits.read_json(tmp_path, "preset")
    (tmp_path / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(ShapeMoveError, match="not valid JSON"):
        limits.read_json(tmp_path / "deep.json", "preset")


def test_every_reader_words_a_too_large_file_the_same_way(tmp_path, capsys):
    from shapemove.core.data.actions import known_actions as dataset_actions
    from shapemove.core.eval.paraphrase_eval import load_prompts
    from shapemove.core.generation import model_bundle
    from shapemove.core.model_files import MANIFEST, verify_manifest

    with pytest.raises(ShapeMoveError, match=r"the paraphrase prompt list file is 5 MB; paraphrase prompt list "
                                             r"files larger than 4 MB are refused"):
        load_prompts(_sparse(tmp_path / "prompts.json", 5 << 20))
    d = tmp_path / "model"
    d.mkdir()
    _sparse(d / MANIFEST, 5 << 20)
    with pytest.raises(ShapeMoveError, match=r"manifest.json: the model manifest file is 5 MB; model manifest files "
                                             r"larger than 4 MB are refused \(re-export or re-train the model\)"):
        verify_manifest(d)
    data = tmp_path / "built"
    data.mkdir()
    _sparse(data / "meta.jsonl", 300 << 20)
    with pytest.raises(ShapeMoveError, match=r"meta.jsonl: the meta.jsonl file is 300 MB; meta.jsonl files larger "
                                             r"than 256 MB are refused \(rebuild the dataset"):
        dataset_actions(data)
    # an optional file (the panel's prompt suggestions): [] with a note, once, never a traceback
    (d / "savae.pt").write_bytes(b"x")
    (d / "t5").mkdir()
    _sparse(d / "t5" / "known_texts.json", 65 << 20)
    capsys.readouterr()
    assert model_bundle.known_actions(d) == [] and model_bundle.known_actions(d, 3) == []
    err = capsys.readouterr().err
    assert err.count("note: no prompt suggestions") == 1
    assert "the known-texts file is 65 MB; known-texts files larger than 64 MB are refused" in err
    (d / "t5" / "known_texts.json").write_text(json.dumps({"actions": [["walk", 9], ["kick", 2], [3, 1]]}))
    os.utime(d / "t5" / "known_texts.json", ns=(1, 1))  # a new version of the file: read again
    assert model_bundle.known_actions(d) == ["walk", "kick"] and model_bundle.known_actions(d, 1) == ["walk"]
    assert capsys.readouterr().err == ""


def _built(tmp_path, jsonl=None, per_clip=None) -> Path:
    root = tmp_path / "built"
    (root / "meta").mkdir(parents=True)
    for cid, meta in (per_clip or {}).items():
        (root / "meta" / f"{cid}.json").write_text(meta if isinstance(meta, str) else json.dumps(meta))
    if jsonl is not None:
        (root / "meta.jsonl").write_text("".join((m if isinstance(m, str) else json.dumps(m)) + "\n" for m in jsonl))
    return root


def test_read_meta_one_definition_for_both_readers(tmp_path, capsys):
    from shapemove.core.data.actions import known_actions, stored_labels
    from shapemove.core.data.built_meta import read_meta
    from shapemove.core.eval.action_classifier import clip_actions

    walk = {"id": "a", "split": "train", "labels": {"actions": ["walk", "turn"]}}
    composed = {"id": "c", "split": "train", "labels": {"actions": ["walk", "kick"], "sequence": ["walk", "kick"]}}
    root = _built(tmp_path, jsonl=[{"id": "a", "split": "train", "labels": {"actions": ["run"]}}, walk, composed, ""],
                  per_clip={"b": {"id": "b", "split": "test", "labels": {"actions": ["wave"]}},
                            "a": {"id": "a", "labels": {"actions": ["jump"]}}, "bad": "{not json",
                            "c": {"id": "c", "labels": {"actions": ["spin"], "sequence": ["spin", "walk"]}}})
    metas = read_meta(root, ["a", "b", "c", "bad", "none"])
    assert metas["a"] == walk and metas["c"] == composed  # meta.jsonl first, its last line for an id
    assert metas["b"]["labels"]["actions"] == ["wave"]    # not in meta.jsonl: meta/b.json
    assert metas["bad"] == {} and metas["none"] == {}
    # the classifier's view: composed "A, then B" clips have no single action
    assert clip_actions(root, ["a", "b", "c", "bad", "none"]) == {"a": ["walk", "turn"], "b": ["wave"], "c": [],
                                                                 "bad": [], "none": []}
    # the vocabulary's view: every clip of meta.jsonl counts, composed ones too
    assert known_actions(root) == [("walk", 2), ("kick", 1), ("run", 1), ("turn", 1)]
    assert known_actions(root, split="test") == []
    (root / "meta.jsonl").unlink()
    assert known_actions(root) == [("jump", 1), ("spin", 1), ("wave", 1)]  # meta/*.json; bad.json skipped
    assert clip_actions(root, ["a", "c"]) == {"a": ["jump"], "c": []}
    capsys.readouterr()
    assert stored_labels(root, "bad") == {} and stored_labels(root, "bad") == {}
    assert stored_labels(root, "b") == {"actions": ["wave"]}
    _sparse(root / "meta" / "huge.json", 2 << 20)
    assert stored_labels(root, "huge") == {}
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "huge.json: the clip meta file is 2 MB; clip meta files larger than 1 MB" in err[0]


def test_meta_jsonl_lines_are_refused_with_their_number(tmp_path, monkeypatch):
    from shapemove.core.data import built_meta
    from shapemove.core.data.built_meta import iter_meta, read_meta

    ok = {"id": "a", "labels": {"actions": ["walk"]}}
    root = _built(tmp_path, jsonl=[ok, "", "{broken"])
    with pytest.raises(ShapeMoveError, match=r"meta.jsonl: line 3 is not valid JSON .*; rebuild the dataset"):
        read_meta(root, ["a"])
    root = _built(tmp_path / "2", jsonl=[ok, "[1, 2]"])
    with pytest.raises(ShapeMoveError, match="line 2 is not a JSON object"):
        list(iter_meta(root))
    with pytest.raises(ShapeMoveError, match="not a built dataset"):
        list(iter_meta(tmp_path / "nothing"))
    # meta.jsonl within, beyond, and growing past its bound while it is read line by line (45 bytes a line)
    root = _built(tmp_path / "3", jsonl=[ok] * 4)
    monkeypatch.setattr(built_meta, "MAX_META_BYTES", 200)
    assert [m["id"] for m in iter_meta(root)] == ["a"] * 4  # 180 bytes
    with open(root / "meta.jsonl", "a") as fh:
        fh.write(json.dumps(ok) + "\n")
    with pytest.raises(ShapeMoveError, match="the meta.jsonl file is 225 bytes; meta.jsonl files larger than 200 bytes"):
        list(iter_meta(root))
    root = _built(tmp_path / "4", jsonl=[ok] * 4)
    real = built_meta.check_file_size

    def check_then_grow(path, *args, **kwargs):
        size = real(path, *args, **kwargs)
        with open(path, "a") as fh:  # appended between the size check and the read
            fh.write(json.dumps(ok) + "\n")
        return size

    monkeypatch.setattr(built_meta, "check_file_size", check_then_grow)
    with pytest.raises(ShapeMoveError, match="meta.jsonl: the meta.jsonl file is more than 200 bytes"):
        list(iter_meta(root))
