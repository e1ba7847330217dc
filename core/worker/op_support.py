"""What a job op uses besides its own code: checking its parameters (``param``, ``str_list``:
bad params -> ShapeMoveError naming the op and the parameter) and ``JobCancelled`` (raise it to
stop after the caller cancelled). A leaf of ``core.worker``: ops, jobs_shapemove and the runner
all import it.
"""
from __future__ import annotations

from ..errors import ShapeMoveError


class JobCancelled(Exception):
    """A job may raise this when it sees cancel() is true; it ends as a cancelled result."""


_REQUIRED = object()


def param(params: dict, op: str, name: str, types, default=_REQUIRED):
    """params[name] checked against ``types`` (a type or tuple); missing -> default or an error."""
    if name not in params or params[name] is None:
        if default is _REQUIRED:
            raise ShapeMoveError(f"op {op!r}: missing parameter {name!r}")
        return default
    value = params[name]
    types = types if isinstance(types, tuple) else (types,)
    if isinstance(value, bool) and bool not in types or not isinstance(value, types):
        want = " or ".join(t.__name__ for t in types)
        raise ShapeMoveError(f"op {op!r}: parameter {name!r} must be {want}, got {type(value).__name__}")
    return value


def str_list(params, op, name, default=_REQUIRED):
    value = param(params, op, name, list, default)
    if value is not None and not all(isinstance(v, str) for v in value):
        raise ShapeMoveError(f"op {op!r}: parameter {name!r} must be a list of strings")
    return value
