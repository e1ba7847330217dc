"""Body model for a motion file's ``body_model`` id (a BodyModel, or without torch the numpy
``BodyArrays`` that the scene builder needs)."""
from __future__ import annotations

from ..errors import ShapeMoveError


def load_body(name: str, model_file=None):
    """"openbody-*" -> the bundled OpenBody; "capsule-v1" -> the procedural capsule body;
    an SMPL-family id ("smplx-male", ...) needs ``model_file`` (the user's own model file)."""
    try:
        from ..body.load import load_body_model
    except ImportError as exc:  # no torch (Blender's Python): the numpy view of the same arrays
        return _load_arrays(name, model_file, exc.name or "torch")
    if name == "capsule-v1":
        from .capsule_body import capsule_body

        return capsule_body()
    if name.startswith("openbody"):
        body = load_body_model("openbody")
    elif model_file:
        body = load_body_model(model_file)
    else:
        raise ShapeMoveError(f"the motion was made for body model {name!r}: give its model file (SMPL family), "
                             "or use a motion made for openbody")
    if str(body.name) != name:
        raise ShapeMoveError(f"the motion was made for body model {name!r} but the loaded one is {body.name!r}")
    return body


def _load_arrays(name: str, model_file, missing: str):
    from ..body.body_arrays import load_body_arrays

    if name.startswith("openbody"):
        body = load_body_arrays("openbody")
    elif model_file:
        body = load_body_arrays(model_file)
    else:
        raise ShapeMoveError(f"body model {name!r} needs {missing} here, or give its model file (SMPL family); "
                             "motions made for openbody work without it")
    if str(body.name) != name:
        raise ShapeMoveError(f"the motion was made for body model {name!r} but the loaded one is {body.name!r}")
    return body
