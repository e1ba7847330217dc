"""The repository root *is* the package ``shapemove`` (it is also the Blender extension root),
so the package list is computed here: every sub-package found under the root, prefixed."""
from setuptools import find_packages, setup

SKIP = ["tests", "tests.*", "tools", "tools.*", "build", "build.*", ".venv", ".venv.*"]

setup(
    packages=["shapemove"] + ["shapemove." + p for p in find_packages(".", exclude=SKIP)],
    package_data={"shapemove": ["blender_manifest.toml", "assets/*", "defaults/*", "defaults/**/*"]},
)
