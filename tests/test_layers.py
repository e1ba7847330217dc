"""Data flows one way (docs/ARCHITECTURE.md, issue #27): the product does not depend on the evaluation,
and the body models do not reach up into the dataset builder or the scene maths. Every import counts,
function-local ones included (the same reading as tests/test_import_cycles.py)."""
from __future__ import annotations

import ast
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]
CORE = ROOT / "core"


def imported_modules(path: Path, root: Path = ROOT) -> set[str]:
    """Dotted names (relative to the package root, e.g. ``core.eval.tma_embed``) of what ``path`` imports,
    at module level or inside functions; imports of other packages are left out."""
    rel = path.relative_to(root).with_suffix("")
    pkg = list(rel.parts[:-1])  # the package a relative import starts from (an __init__'s own package too)
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg[: len(pkg) - (node.level - 1)] if node.level > 1 else pkg
                mod = ".".join(base + ([node.module] if node.module else []))
            elif node.module and node.module.startswith("shapemove."):
                mod = node.module[len("shapemove."):]
            else:
                continue
            out.add(mod)
            for a in node.names:  # `from .. import eval`: the name is itself a module
                sub = root.joinpath(*f"{mod}.{a.name}".split("."))
                if sub.is_dir() or sub.with_suffix(".py").is_file():
                    out.add(f"{mod}.{a.name}")
        elif isinstance(node, ast.Import):
            out.update(a.name[len("shapemove."):] for a in node.names if a.name.startswith("shapemove."))
    return out


def offenders(layer: str, forbidden: tuple[str, ...]) -> list[str]:
    bad = []
    for path in sorted((CORE / layer).rglob("*.py")):
        for mod in sorted(imported_modules(path)):
            if any(mod == f or mod.startswith(f + ".") for f in forbidden):
                bad.append(f"{path.relative_to(ROOT)} imports {mod}")
    return bad


def test_the_reader_finds_every_kind_of_import(tmp_path):
    pkg = tmp_path / "core" / "generation"
    pkg.mkdir(parents=True)
    (tmp_path / "core" / "eval").mkdir()
    (pkg / "x.py").write_text("import os\nfrom . import y\nfrom ..eval.tma_embed import load_tma\n"
                              "def f():\n    from .. import eval\n    import shapemove.core.scene.pose\n")
    mods = imported_modules(pkg / "x.py", tmp_path)
    assert {"core.generation", "core.eval.tma_embed", "core", "core.eval", "core.scene.pose"} <= mods
    assert "os" not in mods


def test_generation_does_not_import_the_evaluation():
    """The product picks its best candidate through the TMA beside the model (core/models/tma_embed.py),
    not through core/eval/."""
    assert offenders("generation", ("core.eval",)) == []


def test_body_does_not_import_the_scene():
    """core/scene/ builds on the body (rig data, poses); the body never reaches up into it."""
    assert offenders("body", ("core.scene",)) == []


def test_body_does_not_import_the_dataset_builder():
    """Shape words are read by the leaf core/text/shape_words.py (issue #25), not by the dataset builder."""
    assert offenders("body", ("core.data",)) == []
