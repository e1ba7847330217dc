"""A developer script of ``tools/`` loaded as a module, for the tests of its functions."""
import importlib.util
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[1] / "tools"


def load_tool(name: str, as_name: str | None = None):
    """``tools/<name>.py`` executed as a module named ``as_name`` (default: ``name``)."""
    spec = importlib.util.spec_from_file_location(as_name or name, TOOLS / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod
