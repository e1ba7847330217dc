"""`python -m shapemove COMMAND --help` ends with an example of that command (an argparse epilog from
cli.EXAMPLES), and every example parses with the command's own options; tests/test_docs_examples.py
runs them, since each is also an example of docs/command-line.md."""
from __future__ import annotations

import contextlib
import io
import shlex

import pytest

from shapemove.cli import COMMANDS, EXAMPLES, main


def help_text(argv: list[str]) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit) as exc:
        main([*argv, "--help"])
    assert exc.value.code == 0
    return out.getvalue()


@pytest.mark.parametrize("key", sorted(set(COMMANDS) | set(EXAMPLES)))
def test_help_ends_with_an_example(key):
    assert key in EXAMPLES, f"`{key}` has no example in cli.EXAMPLES"
    example = EXAMPLES[key]
    assert example.startswith("python -m shapemove " + key.split()[0] + " ")
    text = help_text(key.split()).rstrip().splitlines()
    assert text[-2:] == ["example:", "  " + example], "\n".join(text[-4:])


def test_the_overview_ends_with_an_example():
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["--help"]) == 0
    assert out.getvalue().rstrip().splitlines()[-1].strip() == EXAMPLES["demo"]
