"""Body model by id, as stored in motion files (``body_model``)."""
from __future__ import annotations

from ..errors import ShapeMoveError


def load_body(name: str):
    """"openbody-*" -> OpenBody.load(); "capsule-v1" -> the procedural capsule body."""
    if name.startswith("openbody"):
        from ..body.openbody import OpenBody

        body = OpenBody.load()
        if str(body.name) != name:
            raise ShapeMoveError(f"the motion was made for body model {name!r} but the installed one is {body.name!r}")
        return body
    if name == "capsule-v1":
        from .capsule_body import capsule_body

        return capsule_body()
    raise ShapeMoveError(f"unknown body model {name!r}: expected openbody-v1 or capsule-v1")
