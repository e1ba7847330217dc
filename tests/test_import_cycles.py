"""No import cycles among the project's modules, function-local imports included.

Imports are read with ``ast`` (no module is executed), so a cycle hidden behind an import inside a
function counts the same as one at the top of a file. ``from . import name`` counts as an import of
the sub-module ``name`` when such a module exists, else of the package ``__init__``. Imports by name
(``importlib.import_module("..x", __name__)``) count too: a constant name is one edge, an f-string
(``f".{name}"``) an edge to every module whose name starts with its constant prefix.
"""
from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("core", "shapemove_addon", "cli", "bench", "tools")


def _module_files(root: Path, packages) -> dict[str, Path]:
    """Dotted module name (relative to the ``shapemove`` package) -> file."""
    out: dict[str, Path] = {}
    for top in packages:
        for path in sorted((root / top).rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


def _resolve(module: str, is_package: bool, level: int, target: str | None) -> str:
    base = module.split(".") if is_package else module.split(".")[:-1]
    if level > 1:
        base = base[: len(base) - (level - 1)]
    if target:
        base = base + target.split(".")
    return ".".join(base)


def _by_name(node: ast.Call, name: str, is_package: bool, files) -> list[str]:
    """The modules an ``import_module(...)`` call may import (all that match an f-string's prefix)."""
    if not node.args:
        return []
    arg = node.args[0]
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        text, exact = arg.value, True
    elif isinstance(arg, ast.JoinedStr) and arg.values and isinstance(arg.values[0], ast.Constant):
        text, exact = str(arg.values[0].value), False
    else:
        return []
    level = len(text) - len(text.lstrip("."))
    rest = text[level:]
    if level:
        prefix = _resolve(name, is_package, level, None)
        prefix = f"{prefix}.{rest}" if prefix else rest
    elif rest.startswith("shapemove."):
        prefix = rest[len("shapemove."):]
    else:
        return []
    if exact:
        return [prefix.rstrip(".")]
    return [m for m in files if m.startswith(prefix) and m != prefix.rstrip(".")]


def import_graph(root: Path = ROOT, packages=PACKAGES) -> dict[str, set[str]]:
    """Module -> the project modules it imports anywhere in its file (top level, in functions,
    or by name), with the packages an import initialises on the way."""
    files = _module_files(root, packages)
    graph: dict[str, set[str]] = {name: set() for name in files}
    for name, path in files.items():
        is_package = path.name == "__init__.py"
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
            targets: list[str] = []
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = _resolve(name, is_package, node.level, node.module)
                elif node.module and node.module.startswith("shapemove."):
                    base = node.module[len("shapemove."):]
                else:
                    continue
                for alias in node.names:
                    sub = f"{base}.{alias.name}" if base else alias.name
                    targets.append(sub if sub in files else base)
            elif isinstance(node, ast.Import):
                targets = [a.name[len("shapemove."):] for a in node.names if a.name.startswith("shapemove.")]
            elif isinstance(node, ast.Call) and "import_module" in (getattr(node.func, "attr", None),
                                                                    getattr(node.func, "id", None)):
                targets = _by_name(node, name, is_package, files)
            for target in targets:
                # importing a.b.c runs a/__init__ and a/b/__init__ too
                parts = target.split(".")
                for i in range(1, len(parts) + 1):
                    dep = ".".join(parts[:i])
                    # a package that contains the importer is already being imported: no edge
                    if dep in files and dep != name and not (name + ".").startswith(dep + "."):
                        graph[name].add(dep)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def _tree(tmp_path: Path, files: dict[str, str]) -> Path:
    for rel, text in files.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    return tmp_path


def test_cycles_finds_strongly_connected_modules():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []
    assert cycles({"a": {"b"}, "b": {"a"}, "c": {"d"}, "d": {"c"}}) == [["a", "b"], ["c", "d"]]


def test_graph_sees_cycles_behind_function_local_imports(tmp_path):
    # pkg.a imports pkg.b at the top; pkg.b imports pkg.a only inside a function
    root = _tree(tmp_path, {
        "pkg/__init__.py": "",
        "pkg/a.py": "from .b import g\n",
        "pkg/b.py": "def g():\n    from .a import f\n    return f\n",
        "pkg/c.py": "def h():\n    if True:\n        from . import d\n",
        "pkg/d.py": "class D:\n    def m(self):\n        from .sub.e import x\n",
        "pkg/sub/__init__.py": "",
        "pkg/sub/e.py": "import shapemove.pkg.c\n",
    })
    graph = import_graph(root, ("pkg",))
    assert graph["pkg.b"] == {"pkg.a"} and graph["pkg.a"] == {"pkg.b"}
    # importing pkg.sub.e initialises pkg.sub first; a package never depends on its own parent
    assert graph["pkg.d"] == {"pkg.sub", "pkg.sub.e"} and graph["pkg.sub.e"] == {"pkg.c"}
    assert cycles(graph) == [["pkg.a", "pkg.b"], ["pkg.c", "pkg.d", "pkg.sub.e"]]


def test_graph_sees_imports_by_name(tmp_path):
    root = _tree(tmp_path, {
        "pkg/__init__.py": "",
        "pkg/cmd/__init__.py": "import importlib\ndef run(n):\n    return importlib.import_module(f'.{n}', __name__)\n",
        "pkg/cmd/go.py": "def f():\n    from importlib import import_module\n    import_module('...pkg.tool', __name__)\n",
        "pkg/tool.py": "def f():\n    from .cmd import run\n",
    })
    graph = import_graph(root, ("pkg",))
    assert graph["pkg.cmd"] == {"pkg.cmd.go"}
    assert graph["pkg.cmd.go"] == {"pkg.tool"}
    assert cycles(graph) == [["pkg.cmd", "pkg.cmd.go", "pkg.tool"]]


def test_graph_of_the_project_has_its_known_edges():
    graph = import_graph()
    assert len(graph) > 100
    # top-level, function-local and by-name imports of the real tree
    assert "core.errors" in graph["cli"]
    assert "core.train.train_vae" in graph["cli.train"]  # import_module(f"...core.train.train_{kind}")
    assert "core.motion.features" in graph["core.motion"]  # PEP 562 lazy names


def test_no_import_cycles():
    found = cycles(import_graph())
    assert not found, "import cycles (break them with a leaf module):\n" + "\n".join(
        " <-> ".join(c) for c in found
    )
