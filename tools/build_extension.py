"""Build the Blender extension zip: ``python tools/build_extension.py [--out dist]``.

Packs the repository root (the extension's root: ``blender_manifest.toml`` and ``__init__.py`` at
the top of the zip) into ``<out>/<id>-<version>.zip``, leaving out every path matched by the
manifest's ``[build] paths_exclude_pattern`` (gitignore-style: a leading "/" anchors to the root,
a trailing "/" matches folders only, "*" globs within a name) and the output folder itself.
Entries are sorted with fixed timestamps, so the same tree gives the same zip.
"""
from __future__ import annotations

import argparse
import fnmatch
import os
import sys
import tomllib
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# build/run outputs that must never be shipped even if the manifest forgets them
ALWAYS_EXCLUDE = ["/dist/", "/data/", "/.cache/", "/.venv/", "/.git/", ".pytest_cache/", "/out/", "/runs/",
                  "__pycache__/", "*.pyc", "*.tmp"]


def _matches(rel: str, is_dir: bool, pattern: str) -> bool:
    dir_only = pattern.endswith("/")
    pat = pattern.rstrip("/")
    if dir_only and not is_dir:
        return False
    if pat.startswith("/"):
        return fnmatch.fnmatchcase(rel, pat[1:])
    if "/" in pat:  # relative path pattern: anchored as in gitignore
        return fnmatch.fnmatchcase(rel, pat)
    return fnmatch.fnmatchcase(rel.rsplit("/", 1)[-1], pat)


def excluded(rel: str, is_dir: bool, patterns) -> bool:
    return any(_matches(rel, is_dir, p) for p in patterns)


def files_to_pack(root: Path, patterns) -> list[str]:
    """Relative posix paths of the files to ship, sorted."""
    out = []
    for dirpath, dirnames, filenames in os.walk(root):
        base = Path(dirpath).relative_to(root).as_posix()
        prefix = "" if base == "." else base + "/"
        dirnames[:] = sorted(d for d in dirnames if not excluded(prefix + d, True, patterns))
        out += [prefix + f for f in filenames if not excluded(prefix + f, False, patterns)]
    return sorted(out)


def build(out_dir: Path, root: Path = ROOT) -> Path:
    manifest_path = root / "blender_manifest.toml"
    if not manifest_path.is_file():
        raise SystemExit(f"error: no blender_manifest.toml in {root}")
    manifest = tomllib.loads(manifest_path.read_text())
    patterns = list(manifest.get("build", {}).get("paths_exclude_pattern", [])) + ALWAYS_EXCLUDE
    out_dir = Path(out_dir).resolve()
    try:
        patterns.append("/" + out_dir.relative_to(root.resolve()).as_posix() + "/")
    except ValueError:
        pass  # output outside the tree
    files = files_to_pack(root, patterns)
    for required in ("blender_manifest.toml", "__init__.py"):
        if required not in files:
            raise SystemExit(f"error: {required} would not be in the zip (excluded by a pattern?)")
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / f"{manifest['id']}-{manifest['version']}.zip"
    tmp = target.with_name(target.name + ".tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        for rel in files:
            info = zipfile.ZipInfo(rel, date_time=(2025, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zf.writestr(info, (root / rel).read_bytes())
    os.replace(tmp, target)
    return target


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=ROOT / "dist", help="output folder (default: dist)")
    args = p.parse_args(argv)
    path = build(args.out)
    with zipfile.ZipFile(path) as zf:
        n = len(zf.namelist())
    print(f"wrote {path} ({n} files, {path.stat().st_size / 1e6:.1f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
