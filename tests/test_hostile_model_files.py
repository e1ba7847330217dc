"""Hostile and damaged model files (issue 11): planted checkpoints that run code, corrupted bytes,
truncated or garbage files, a T5 folder without its tokenizer. Loading must refuse each one with a
ShapeMoveError sentence; payloads only touch a marker in tmp_path, asserted NOT to exist."""
import json
import os
import re
from pathlib import Path

import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.model_files import MANIFEST, verify_file, verify_manifest, write_manifest
from shapemove.core.train.checkpoint import load_checkpoint, save_checkpoint

ROOT = Path(__file__).resolve().parents[1]


class _Call:
    def __init__(self, func, *args):
        self.func, self.args = func, args

    def __reduce__(self):
        return self.func, self.args


def _flip(path: Path, offset: int) -> None:
    b = bytearray(path.read_bytes())
    b[offset] ^= 0x40
    path.write_bytes(bytes(b))


def test_planted_checkpoint_never_runs_code(tmp_path):
    """``train t5 --resume`` used torch.load(weights_only=False): a planted last.pt ran code."""
    marker = tmp_path / "marker"
    last = tmp_path / "run" / "last.pt"
    last.parent.mkdir()
    torch.save({"kind": "t5", "model": _Call(exec, f"open({str(marker)!r}, 'w').close()"),
                "metadata": {"format": 1, "kind": "t5"}}, last)
    with pytest.raises(ShapeMoveError, match="cannot read checkpoint"):
        load_checkpoint(last, kind="t5")
    assert not marker.exists()


def test_no_unsafe_loads_in_the_code():
    """weights_only=True everywhere; no pickles allowed in np.load."""
    bad = []
    for folder in ("core", "cli", "shapemove_addon", "tools", "bench"):
        for p in (ROOT / folder).rglob("*.py"):
            text = p.read_text(encoding="utf-8")
            for pattern in (r"weights_only\s*=\s*False", r"allow_pickle\s*=\s*True", r"pickle\.loads?\(",
                            r"torch\.load\((?![^)]*weights_only\s*=\s*True)"):
                bad += [f"{p.relative_to(ROOT)}: {m.group(0)}" for m in re.finditer(pattern, text)]
    allowed = {"core/body/smpl_family.py"}  # its restricted _ModelUnpickler is the one pickle reader
    assert [b for b in bad if b.split(":")[0] not in allowed] == []


def test_checkpoint_with_one_flipped_byte_is_refused(tmp_path):
    """A corrupted byte used to load (and move outputs by centimetres): the manifest catches it."""
    path = tmp_path / "run" / "savae.pt"
    w = torch.randn(300, 100)
    save_checkpoint(path, {"model": {"w": w}}, {"format": 1, "kind": "savae"})
    assert (tmp_path / "run" / MANIFEST).is_file()
    assert torch.equal(load_checkpoint(path, kind="savae")["model"]["w"], w)
    _flip(path, path.stat().st_size // 2)  # inside the tensor data: torch.load alone accepts this
    with pytest.raises(ShapeMoveError, match="damaged or was replaced: its sha256 differs"):
        load_checkpoint(path, kind="savae")
    path.write_bytes(path.read_bytes()[:1000])
    with pytest.raises(ShapeMoveError, match="truncated or swapped"):
        load_checkpoint(path, kind="savae")
    # a second checkpoint in the same folder keeps the first one's entry
    save_checkpoint(tmp_path / "run" / "last.pt", {"model": {}}, {"format": 1, "kind": "savae"})
    entries = json.loads((tmp_path / "run" / MANIFEST).read_text())["files"]
    assert sorted(entries) == ["last.pt", "savae.pt"]


def test_checkpoint_without_manifest_loads_with_a_note(tmp_path, capsys):
    path = tmp_path / "old.pt"
    torch.save({"model": {}, "metadata": {"format": 1, "kind": "savae"}}, path)
    load_checkpoint(path, kind="savae")
    assert "not listed in any manifest.json" in capsys.readouterr().err
    path.write_bytes(b"garbage" * 10)
    with pytest.raises(ShapeMoveError, match="cannot read checkpoint"):
        load_checkpoint(path, kind="savae")


def test_manifest_folder_checks(tmp_path):
    d = tmp_path / "model"
    (d / "t5").mkdir(parents=True)
    (d / "savae.pt").write_bytes(b"a" * 100)
    (d / "t5" / "model.safetensors").write_bytes(b"b" * 100)
    (d / "t5" / MANIFEST).write_text("{}")  # a stale nested manifest is replaced by the top one
    write_manifest(d)
    assert not (d / "t5" / MANIFEST).exists()
    assert verify_manifest(d / "t5") and verify_file(d / "savae.pt")
    (d / "t5" / "model.safetensors").write_bytes(b"c" * 100)  # same size, other bytes
    with pytest.raises(ShapeMoveError, match="sha256 differs"):
        verify_manifest(d / "t5")
    os.remove(d / "t5" / "model.safetensors")
    with pytest.raises(ShapeMoveError, match="is missing"):
        verify_manifest(d)
    (d / MANIFEST).write_text('{"format": "shapemove-manifest/1", "files": {"../../x": {"sha256": "0", "bytes": 1}}}')
    with pytest.raises(ShapeMoveError, match="outside its folder"):
        verify_manifest(d)
    (d / MANIFEST).write_text("[" * 100000)
    with pytest.raises(ShapeMoveError, match="manifest.json is damaged"):
        verify_manifest(d)


# -- a real (tiny) ShapeMove T5 folder --------------------------------------------------------
@pytest.fixture(scope="module")
def t5_folder(tmp_path_factory):
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5, T5Size
    from shapemove.core.models.tokenizer import tokenizer_from_sentencepiece, train_sentencepiece

    d = tmp_path_factory.mktemp("t5")
    texts = ["A person walks forward.", "Someone waves with the left hand.", "a tall, heavy-set man"] * 40
    tok = tokenizer_from_sentencepiece(train_sentencepiece(texts, d / "sp", vocab_size=120))
    torch.manual_seed(0)
    ShapeMoveT5.build(tok, T5Size.tiny()).save(d / "t5", tok)
    return d / "t5"


def _copy(src: Path, dst: Path) -> Path:
    import shutil

    shutil.copytree(src, dst)
    return dst


def test_t5_save_writes_manifest_and_loads(t5_folder):
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    files = json.loads((t5_folder / MANIFEST).read_text())["files"]
    assert {"model.safetensors", "beta_head.safetensors", "tokenizer.json", "config.json", "shapemove.json"} <= set(files)
    model, tok = ShapeMoveT5.load(t5_folder)
    assert tok.convert_tokens_to_ids("walks") != tok.unk_token_id or len(tok("walks").input_ids) > 1


@pytest.mark.parametrize("damage, match", [
    (lambda d: os.remove(d / "tokenizer.json"), "incomplete: tokenizer.json missing"),
    (lambda d: os.remove(d / "model.safetensors"), "incomplete: model.safetensors missing"),
    (lambda d: _flip(d / "model.safetensors", (d / "model.safetensors").stat().st_size - 50), "sha256 differs"),
    (lambda d: (d / "beta_head.safetensors").write_bytes((d / "beta_head.safetensors").read_bytes()[:200]),
     "truncated or swapped"),
    (lambda d: (d / "config.json").write_text("{not json"), "damaged or was replaced"),
])
def test_damaged_t5_folder_with_manifest(t5_folder, tmp_path, damage, match):
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    d = _copy(t5_folder, tmp_path / "t5")
    damage(d)
    with pytest.raises(ShapeMoveError, match=match):
        ShapeMoveT5.load(d)


@pytest.mark.parametrize("damage", [
    lambda d: (d / "config.json").write_text("{not json"),
    lambda d: (d / "config.json").write_text('{"model_type": "t5", "d_model": "huge"}'),
    lambda d: (d / "shapemove.json").write_text("[1, 2"),
    lambda d: (d / "shapemove.json").write_text("[1, 2]"),
    lambda d: (d / "tokenizer.json").write_text('{"version": "1.0", "model": 5}'),
    lambda d: (d / "model.safetensors").write_bytes((d / "model.safetensors").read_bytes()[:300]),
    lambda d: (d / "beta_head.safetensors").write_bytes(b"\xff" * 64),
])
def test_damaged_t5_folder_without_manifest_is_a_sentence(t5_folder, tmp_path, damage):
    """Older exports have no manifest: a damaged file must still be a sentence, not a traceback."""
    from shapemove.core.models.shapemove_t5 import ShapeMoveT5

    d = _copy(t5_folder, tmp_path / "t5")
    os.remove(d / MANIFEST)
    damage(d)
    with pytest.raises(ShapeMoveError, match="damaged|unsupported model format"):
        ShapeMoveT5.load(d)
