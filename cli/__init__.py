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
    "body": ("body", "body model facts and the bodies shape texts describe: `body info|shape|render`"),
    "data": ("data", "build a training dataset from motion capture: `data build`"),
    "train": ("train", "train a model: `train vae|t5|tma`"),
    "eval": ("eval", "evaluate: `eval KIND` (recon, generate, retarget, paraphrase, parts, sequences, shape, ...)"),
    "retarget": ("retarget", "move a motion onto another body through the SA-VAE"),
    "retarget-rig": ("retarget_rig", "bake a motion onto your own armature in a .blend (Rigify, Mixamo, CC, ...)"),
    "generate": ("generate", "text prompt -> body shape and motion (.npz)"),
    "sequence": ("sequence", "a timeline of prompts -> one motion with a segment per prompt (.npz)"),
    "search": ("search", "rank a folder of motions by a text query (TMA)"),
    "blend": ("blend", "build a .blend scene from a motion (.npz), optionally render a frame"),
    "render": ("render", "generate and render a batch of prompts headless"),
    "batch": ("batch", "join the manifests of a batch's shards: `batch merge`"),
    "demo": ("demo", "prompt -> .blend + rendered preview with the default model"),
    "worker": ("worker", "serve jobs over stdin/stdout (JSON lines) for the Blender extension"),
    "bench": ("bench", "speed benchmarks that print ratios against a baseline run alongside"),
}


from ..core.errors import ShapeMoveError as UserError  # noqa: E402  (one error type everywhere)

P = "python -m shapemove "
# `python -m shapemove COMMAND [ACTION] --help` ends with one of these; each is also an example of
# docs/command-line.md, which tests/test_docs_examples.py runs (so a renamed option fails a test)
EXAMPLES: dict[str, str] = {
    "body": P + "body info",
    "body info": P + "body info",
    "body shape": P + 'body shape "a muscular 188 cm man, 92 kg"',
    "body render": P + 'body render "a tall, heavy-set man" "a slim teenage girl" --out bodies.png',
    "data": P + "data build --source ../shared/data/*.tar.xz --out data/built",
    "data build": P + "data build --source ../shared/data/*.tar.xz --out data/built",
    "data compose": P + "data compose --data data/built --count 800 --seed 0",
    "data compose-parts": P + "data compose-parts --data data/built --count 800 --seed 0",
    "data mirror": P + "data mirror --data data/built",
    "train": P + "train vae --data data/built --config configs/default_vae.json --out runs/vae",
    "train vae": P + "train vae --data data/built --config configs/default_vae.json --out runs/vae",
    "train tma": P + "train tma --data data/built --config configs/default_tma.json --out runs/tma",
    "train head": P + "train head --data data/built --out runs/head",
    "train t5": P + "train t5 --data data/built --config configs/default_t5.json --vae runs/vae/savae.pt --out runs/t5",
    "eval": P + "eval shape --bodies 200 --json out/eval_shape.json",
    "eval recon": P + "eval recon --data data/built --split test --checkpoint weights/default/savae.pt --max-clips 40 "
                      "--json out/eval_recon.json",
    "eval generate": P + "eval generate --data data/built --split test --max-clips 60 --json out/eval_generate.json",
    "eval retarget": P + "eval retarget --data data/built --checkpoint weights/default/savae.pt "
                         "--json out/eval_retarget.json",
    "eval paraphrase": P + "eval paraphrase --data data/built --prompts configs/heldout_paraphrases_blind.json "
                           "--json out/eval_paraphrase_blind.json",
    "eval shape": P + "eval shape --bodies 200 --json out/eval_shape.json",
    "eval shape-words": P + "eval shape-words --path auto --json out/eval_shape_words.json",
    "eval speed": P + "eval speed --data data/built --checkpoint weights/default/savae.pt --feet --json out/eval_speed.json",
    "retarget": P + 'retarget --motion walk.bvh --shape-text "A person standing 190 cm tall" --out tall_walk.npz',
    "retarget-rig": P + "retarget-rig --motion wave.npz --blend hero.blend --armature Hero --out hero_wave.blend "
                        "--preset mixamo",
    "generate": P + 'generate --prompt "a person waves" --shape-text "a short, slim woman" --seconds 4 --out wave.npz',
    "sequence": P + 'sequence --prompt "a person walks forward" --seconds 4 --prompt "a person sits down" --seconds 2 '
                    '--out seq.npz',
    "search": P + 'search --library data/built --query "someone kicks" --top 5',
    "blend": P + "blend --motion wave.npz --out wave.blend --render wave.png",
    "render": P + "render --prompts prompts.txt --out renders/ --frames 4 --resolution 320 320",
    "batch": P + "batch merge shards/manifest-0-of-2.jsonl shards/manifest-1-of-2.jsonl --out merged/",
    "batch merge": P + "batch merge shards/manifest-0-of-2.jsonl shards/manifest-1-of-2.jsonl --out merged/",
    "demo": P + 'demo --prompt "someone kicks with the left leg" --shape-text "a short, slim woman" --out out/kick',
    "worker": P + "worker --list",
    "bench": P + "bench sliders --quick --json out/bench_sliders.json",
}


class _HelpFormatter(argparse.HelpFormatter):
    """Wraps descriptions as usual but prints the example epilog as written (one command a line)."""

    def _fill_text(self, text, width, indent):
        if text.startswith("example:"):
            return "".join(indent + line for line in text.splitlines(keepends=True))
        return super()._fill_text(text, width, indent)


def with_example(parser: argparse.ArgumentParser, key: str) -> argparse.ArgumentParser:
    """Let ``parser``'s help end with ``EXAMPLES[key]`` (when there is one); its sub-commands' too."""
    if key in EXAMPLES:
        parser.epilog = f"example:\n  {EXAMPLES[key]}"
        parser.formatter_class = _HelpFormatter
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                with_example(child, f"{key} {name}")
    return parser



def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m shapemove", description=__doc__.splitlines()[0],
                                     epilog=f"example:\n  {EXAMPLES['demo']}", formatter_class=_HelpFormatter)
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
    with_example(sub, name)
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
