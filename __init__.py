"""ShapeMove for Blender: text prompt -> shaped, rigged, keyframed human body.

This file is both the Blender extension entry point (``register``/``unregister``) and the
top of the Python package ``shapemove`` used from the command line (``python -m shapemove``).
Nothing here imports bpy at import time, so the command line works without Blender.
"""


def _manifest_version() -> str:
    """The version, written once: in blender_manifest.toml (Blender reads it there; pyproject.toml
    takes it from here)."""
    import os
    import tomllib

    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "blender_manifest.toml"), "rb") as f:
        return str(tomllib.load(f)["version"])


__version__ = _manifest_version()


def register():
    from .shapemove_addon import register as _register

    _register()


def unregister():
    from .shapemove_addon import unregister as _unregister

    _unregister()
