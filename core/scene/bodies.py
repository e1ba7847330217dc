"""Body model for a motion file's ``body_model`` id (a BodyModel, or without torch the numpy
``BodyArrays`` that the scene builder needs)."""
from __future__ import annotations

from ..constants import is_openbody
from ..errors import ShapeMoveError


def load_body(name: str, model_file=None):
    """"openbody-*" -> the bundled OpenBody; an SMPL-family id ("smplx-male", ...) needs
    ``model_file`` (the user's own model file). Test bodies (the capsule) are not known by name.
    Without torch (Blender's own Python) the same arrays come as numpy ``BodyArrays``."""
    try:
        from ..body.load import load_body_model as loader
    except ImportError:
        from ..body.body_arrays import load_body_arrays as loader
    if is_openbody(name):
        body = loader("openbody")
    elif model_file:
        body = loader(model_file)
    else:
        raise ShapeMoveError(f"the motion was made for body model {name!r}: give its model file (SMPL family), "
                             "or use a motion made for openbody")
    if str(body.name) != name:
        raise ShapeMoveError(f"the motion was made for body model {name!r} but the loaded one is {body.name!r}")
    return body
