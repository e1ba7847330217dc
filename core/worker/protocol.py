"""The worker's wire format: one JSON object per line (UTF-8) on stdin (requests) / stdout (responses).

Request:   {"id": "j1", "op": "body_info", "params": {...}}          (params optional, an object)
Responses, all carrying the request's "id" (null when a line could not be parsed far enough):
  {"id", "type": "progress", "fraction": 0..1, "message": str}
  {"id", "type": "result",   "result": {...}, "cancelled": bool}
  {"id", "type": "error",    "message": str, "error_type": str}   ("ShapeMoveError" = bad input)
  {"id", "type": "log",      "message": str}                      (stray output of a job)
Control ops answered at once, even while a job runs: "ping", "cancel" (params {"job": id}),
"shutdown". Every other op is a job, run one at a time in arrival order.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import PurePath

from ..errors import ShapeMoveError

PROTOCOL_VERSION = 1
CONTROL_OPS = ("ping", "cancel", "shutdown")
RESPONSE_TYPES = ("progress", "result", "error", "log")
MAX_LINE = 16 * 1024 * 1024  # a request line longer than this is refused (the server never reads it whole)
MAX_DEPTH = 32  # nesting of objects/arrays in a message
MAX_ID_CHARS = 200
MAX_INT_ID = 2**53  # ids must survive a round trip through any JSON reader
MAX_SHUTDOWN_WAIT = 600.0


class ProtocolError(ShapeMoveError):
    """A line that is not a valid message. ``request_id`` is the id when it could be read."""

    def __init__(self, message: str, request_id=None):
        super().__init__(message)
        self.request_id = request_id


@dataclass
class Request:
    id: str
    op: str
    params: dict = field(default_factory=dict)


def _json_default(obj):
    """numpy scalars/arrays, torch tensors, paths and sets -> plain JSON values."""
    if isinstance(obj, PurePath):
        return str(obj)
    if isinstance(obj, (set, frozenset, tuple)):
        return list(obj)
    if hasattr(obj, "tolist"):  # numpy arrays and scalars, torch tensors
        return obj.tolist()
    raise TypeError(f"{type(obj).__name__} is not JSON serializable")


def _dumps(obj: dict) -> str:
    try:
        text = json.dumps(obj, default=_json_default, ensure_ascii=False, separators=(",", ":"))
    except (TypeError, ValueError) as exc:
        raise ProtocolError(f"message cannot be written as JSON: {exc}", obj.get("id")) from None
    return text  # json never emits a raw newline inside a value, so this is one line


def _loads(line, what: str) -> dict:
    if isinstance(line, bytes):
        try:
            line = line.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ProtocolError(f"{what} is not UTF-8 ({exc})") from None
    if len(line) > MAX_LINE:
        raise ProtocolError(f"{what} is too long ({len(line)} characters, limit {MAX_LINE})")
    line = line.strip()
    if not line:
        raise ProtocolError(f"empty {what}")
    if _bracket_depth(line) > MAX_DEPTH:
        raise ProtocolError(f"{what} is nested more than {MAX_DEPTH} levels deep")
    try:
        obj = json.loads(line)
    except json.JSONDecodeError as exc:
        raise ProtocolError(f"{what} is not valid JSON ({exc.msg} at column {exc.colno}): {line[:80]!r}") from None
    except (ValueError, RecursionError) as exc:  # e.g. an integer of thousands of digits
        raise ProtocolError(f"{what} cannot be read: {str(exc)[:120]}") from None
    if not isinstance(obj, dict):
        raise ProtocolError(f"{what} must be a JSON object, got {type(obj).__name__}")
    return obj


def _bracket_depth(text: str) -> int:
    """Deepest [ / { nesting outside strings, found without recursion (json.loads would recurse)."""
    if text.count("[") + text.count("{") <= MAX_DEPTH:
        return 0
    depth = deepest = 0
    for m in _BRACKETS.finditer(_STRINGS.sub("", text)):
        if m.group() in "[{":
            depth += 1
            if depth > deepest:
                deepest = depth
                if deepest > MAX_DEPTH:
                    break
        else:
            depth -= 1
    return deepest


_STRINGS = re.compile(r'"(?:[^"\\]|\\.)*"')
_BRACKETS = re.compile(r"[\[\]{}]")


def _check_id(value, what: str):
    if value is None or isinstance(value, bool) or not isinstance(value, (str, int)):
        raise ProtocolError(f"{what} needs an \"id\" (string or integer), got {_short(value)}")
    if isinstance(value, str) and len(value) > MAX_ID_CHARS:
        raise ProtocolError(f"{what} id is {len(value)} characters long (limit {MAX_ID_CHARS})")
    if isinstance(value, int) and abs(value) > MAX_INT_ID:
        raise ProtocolError(f"{what} id {_short(value)} is too large (limit 2**53)")
    return value


def _short(value) -> str:
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**30:
        return "(a very large integer)"
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _check_control(rid, op: str, params: dict) -> None:
    """Parameters of the control ops, checked before the runner uses them."""
    if op == "shutdown" and "timeout" in params:
        t = params["timeout"]
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t) or not 0 <= t <= MAX_SHUTDOWN_WAIT:
            raise ProtocolError(f"request {rid!r}: shutdown \"timeout\" must be a number of seconds from 0 to "
                                f"{MAX_SHUTDOWN_WAIT:g}, got {_short(t)}", rid)
    if op == "cancel":
        _check_id(params.get("job"), f"request {rid!r}: cancel")


# -- requests ----------------------------------------------------------------------------------
def encode_request(request_id, op: str, params: dict | None = None) -> str:
    """One request line (without the newline)."""
    _check_id(request_id, "request")
    if not isinstance(op, str) or not op:
        raise ProtocolError(f"request op must be a non-empty string, got {op!r}", request_id)
    if params is not None and not isinstance(params, dict):
        raise ProtocolError(f"request params must be an object, got {type(params).__name__}", request_id)
    return _dumps({"id": request_id, "op": op, "params": params or {}})


def decode_request(line) -> Request:
    """Parse and validate one request line; raises ProtocolError naming what is wrong."""
    obj = _loads(line, "request line")
    rid = obj.get("id")
    _check_id(rid, "request")
    op = obj.get("op")
    if not isinstance(op, str) or not op or len(op) > MAX_ID_CHARS:
        raise ProtocolError(f"request {rid!r} needs an \"op\" (non-empty string), got {_short(op)}", rid)
    params = obj.get("params", {})
    if params is None:
        params = {}
    if not isinstance(params, dict):
        raise ProtocolError(f"request {rid!r}: \"params\" must be an object, got {type(params).__name__}", rid)
    extra = set(obj) - {"id", "op", "params"}
    if extra:
        raise ProtocolError(f"request {rid!r} has unknown keys: {', '.join(sorted(extra))[:200]}", rid)
    _check_control(rid, op, params)
    return Request(rid, op, params)


# -- responses ---------------------------------------------------------------------------------
def progress(request_id, fraction: float, message: str = "") -> dict:
    return {"id": request_id, "type": "progress", "fraction": fraction, "message": message}


def result(request_id, data: dict | None = None, cancelled: bool = False) -> dict:
    return {"id": request_id, "type": "result", "result": {} if data is None else data, "cancelled": bool(cancelled)}


def error(request_id, message: str, error_type: str = "ShapeMoveError") -> dict:
    return {"id": request_id, "type": "error", "message": message, "error_type": error_type}


def log(request_id, message: str) -> dict:
    return {"id": request_id, "type": "log", "message": message}


def validate_response(msg: dict) -> dict:
    """Check the fields of a response dict (see the module docstring); returns it."""
    if not isinstance(msg, dict):
        raise ProtocolError(f"response must be an object, got {type(msg).__name__}")
    rid, kind = msg.get("id"), msg.get("type")
    if rid is not None:
        _check_id(rid, "response")
    if kind not in RESPONSE_TYPES:
        raise ProtocolError(f"response type must be one of {', '.join(RESPONSE_TYPES)}, got {kind!r}", rid)
    if kind == "progress":
        f = msg.get("fraction")
        if isinstance(f, bool) or not isinstance(f, (int, float)) or not math.isfinite(f) or not 0 <= f <= 1:
            raise ProtocolError(f"progress fraction must be a number in [0, 1], got {f!r}", rid)
    if kind in ("progress", "error", "log") and not isinstance(msg.get("message"), str):
        raise ProtocolError(f"{kind} message must be a string, got {msg.get('message')!r}", rid)
    if kind == "result":
        if not isinstance(msg.get("result"), dict):
            raise ProtocolError(f"result must be an object, got {type(msg.get('result')).__name__}", rid)
        if not isinstance(msg.get("cancelled", False), bool):
            raise ProtocolError("result 'cancelled' must be true or false", rid)
    if kind == "error" and not isinstance(msg.get("error_type", ""), str):
        raise ProtocolError("error 'error_type' must be a string", rid)
    return msg


def encode_response(msg: dict) -> str:
    """One response line (without the newline); numpy/torch values become lists and numbers."""
    validate_response(msg)
    return _dumps(msg)


def decode_response(line) -> dict:
    """Parse and validate one response line; raises ProtocolError naming what is wrong."""
    return validate_response(_loads(line, "response line"))
