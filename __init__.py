"""ShapeMove for Blender: text prompt -> shaped, rigged, keyframed human body.

This file is both the Blender extension entry point (``register``/``unregister``) and the
top of the Python package ``shapemove`` used from the command line (``python -m shapemove``).
Nothing here imports bpy at import time, so the command line works without Blender.
"""

__version__ = "0.1.0"


def register():
    from .shapemove_addon import register as _register

    _register()


def unregister():
    from .shapemove_addon import unregister as _unregister

    _unregister()
