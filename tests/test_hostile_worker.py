"""Hostile worker protocol lines (issue 11): deep nesting, huge ids, bad control parameters and a
300 MB line. Each gets one error response and the worker keeps serving; the long line is never
held in memory whole."""
import io
import json

import pytest

from shapemove.core.worker import protocol as P
from shapemove.core.worker.server import serve


def _serve(lines: list[str]) -> list[dict]:
    out = io.StringIO()
    serve(io.StringIO("".join(line + "\n" for line in lines)), out, jobs={})
    return [json.loads(x) for x in out.getvalue().splitlines()]


@pytest.mark.parametrize("line, match", [
    ("[" * 100000, "nested more than 32 levels"),
    ('{"id": "a", "op": "x", "params": {"p": ' + "[" * 5000 + "]" * 5000 + "}}", "nested more than 32 levels"),
    ('{"id": 1' + "0" * 5000 + ', "op": "ping"}', "cannot be read"),
    ('{"id": 1' + "0" * 40 + ', "op": "ping"}', "too large"),
    ('{"id": "' + "x" * 5000 + '", "op": "ping"}', "characters long"),
    ('{"id": "s", "op": "shutdown", "params": {"timeout": "abc"}}', "timeout\" must be a number"),
    ('{"id": "s", "op": "shutdown", "params": {"timeout": NaN}}', "timeout\" must be a number"),
    ('{"id": "s", "op": "shutdown", "params": {"timeout": 1e999}}', "timeout\" must be a number"),
    ('{"id": "s", "op": "shutdown", "params": {"timeout": -1}}', "timeout\" must be a number"),
    ('{"id": "s", "op": "shutdown", "params": {"timeout": true}}', "timeout\" must be a number"),
    ('{"id": "c", "op": "cancel", "params": {"job": [1, 2]}}', "needs an \"id\""),
    ('{"id": "o", "op": "' + "y" * 1000 + '"}', "needs an \"op\""),
])
def test_bad_line_gets_one_error_and_worker_goes_on(line, match):
    msgs = _serve([line, '{"id": "p", "op": "ping"}', '{"id": "s", "op": "shutdown", "params": {"timeout": 1}}'])
    assert msgs[0]["type"] == "error" and msgs[0]["error_type"] == "ProtocolError", msgs[0]
    assert match in msgs[0]["message"]
    assert len(msgs[0]["message"]) < 400  # the sentence does not echo the payload
    assert msgs[1]["id"] == "p" and msgs[1]["result"]["pong"]
    assert msgs[-1]["result"] == {"shutdown": True}


class _HugeLineStream(io.TextIOBase):
    """stdin whose first line is ``size`` characters, produced on demand (never stored)."""

    def __init__(self, size: int, after: str):
        self.left, self.after, self.biggest = size, after, 0

    def readline(self, size=-1):
        assert size > 0, "the server must bound its reads"
        self.biggest = max(self.biggest, size)
        if self.left > 0:
            n = min(size, self.left)
            self.left -= n
            return "x" * n if self.left else "x" * (n - 1) + "\n"
        line, _, self.after = self.after.partition("\n")
        return line + "\n" if line or self.after else ""


def test_300_mb_line_is_never_read_whole():
    stream = _HugeLineStream(300 * 2**20, '{"id": "p", "op": "ping"}\n')
    out = io.StringIO()
    serve(stream, out, jobs={})
    msgs = [json.loads(x) for x in out.getvalue().splitlines()]
    assert msgs[0]["type"] == "error" and "too long" in msgs[0]["message"]
    assert msgs[1]["result"]["pong"]
    assert stream.biggest <= P.MAX_LINE + 1


def test_valid_control_params_still_work():
    msgs = _serve(['{"id": 7, "op": "cancel", "params": {"job": "nope"}}',
                   '{"id": "s", "op": "shutdown", "params": {"timeout": 0.5}}'])
    assert msgs[0]["result"] == {"job": "nope", "state": "unknown"}
    assert msgs[1]["result"] == {"shutdown": True}
