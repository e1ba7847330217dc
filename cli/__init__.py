"""``python -m shapemove``: one sub-command per module in this folder.

Each command module defines ``add_arguments(parser)`` and ``run(args) -> int``. Modules are
imported only when their command runs, so ``--help`` stays fast and a command never pays for
another one's imports (torch, bpy, transformers).
"""
from __future__ import annotations

import argparse
import importlib
import sys

# name -> (module in this package, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "body": ("body", "body model facts: `body info`"),
    "data": ("data", "build a training dataset from motion capture: `data build`"),
    "train": ("train", "train a model: `train vae|t5|tma`"),
    "eval": ("eval", "evaluate: `eval recon|generate`"),
    "retarget": ("retarget", "move a motion onto another body through the SA-VAE"),
    "retarget-rig": ("retarget_rig", "bake a motion onto your own armature in a .blend (Rigify, Mixamo, CC, ...)"),
    "generate": ("generate", "text prompt -> body shape and motion (.npz)"),
    "search": ("search", "rank a folder of motions by a text query (TMA)"),
    "blend": ("blend", "build a .blend scene from a motion (.npz), optionally render a frame"),
    "render": ("render", "generate and render a batch of prompts headless"),
    "demo": ("demo", "prompt -> .blend + rendered preview with the default model"),
    "worker": ("worker", "serve jobs over stdin/stdout (JSON lines) for the Blender extension"),
    "bench": ("bench", "speed benchmarks that print ratios against a baseline run alongside"),
}


from ..core.errors import ShapeMoveError as UserError  # noqa: E402  (one error type everywhere)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m shapemove", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module, help_text) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        p.set_defaults(_module=module)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    # First pass only finds the command; its module then adds its own arguments.
    if not argv or argv[0] in ("-h", "--help") or argv[0] not in COMMANDS:
        parser.print_help() if not argv or argv[0] in ("-h", "--help") else parser.parse_args(argv)
        return 0 if not argv or argv[0] in ("-h", "--help") else 2
    name = argv[0]
    try:
        module = importlib.import_module(f".{COMMANDS[name][0]}", __name__)
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.endswith(f"cli.{COMMANDS[name][0]}"):
            print(f"error: the `{name}` command is not available in this build", file=sys.stderr)
            return 2
        raise
    sub = argparse.ArgumentParser(prog=f"python -m shapemove {name}", description=COMMANDS[name][1])
    module.add_arguments(sub)
    args = sub.parse_args(argv[1:])
    try:
        return int(module.run(args) or 0)
    except UserError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # read-only folder, a parent that is a file, disk full, ...: a sentence
        from ..core.atomic import os_error_sentence

        where = exc.filename if exc.filename is not None else "a file"
        print(f"error: {os_error_sentence(exc, where, 'use')}", file=sys.stderr)
        return 2
    except MemoryError:
        print("error: out of memory (the input is too large for this machine)", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
