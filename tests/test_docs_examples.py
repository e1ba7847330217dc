"""The manual cannot go stale: every command example in docs/command-line.md runs, in the page's order
in one folder, with tiny or fast options appended where the real run takes minutes (argparse keeps
the last value of an option given twice, so an appended option overrides the page's). Every
`python -m shapemove` line elsewhere in the README and the manual, and every `--help` example, must
be one of the page's, so they run too."""
from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import need_module

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "command-line.md"
PREFIX = "python -m shapemove "

# the dataset the examples build: a few clips of each archive (train, val and test splits all non-empty)
CLIPS = ["dataset-1_walk_feminine_001", "dataset-1_kick_normal_001", "dataset-2_wave-left-hand_elderly_001",
         "cmu_02_01", "cmu_13_10", "cmu_09_01", "HDM_dg_squat1Reps_025_120"]
TRAIN_FAST = ["--config", "tiny", "--steps", "2", "--quiet"]
# (the example's first words, what is appended): minutes become seconds, nothing else changes
FAST = [
    (("data", "build"), ["--only", *CLIPS]),
    (("data", "compose"), ["--count", "2"]),
    (("data", "compose-parts"), ["--count", "2"]),
    (("train",), TRAIN_FAST),
    (("eval", "recon"), ["--max-clips", "2", "--quiet"]),
    (("eval", "generate"), ["--max-clips", "2", "--quiet"]),
    (("eval", "retarget"), ["--max-clips", "1"]),
    (("eval", "paraphrase"), ["--prompts", "tiny_prompts.json", "--quiet"]),
    (("eval", "sequences"), ["--max-prompts", "1", "--quiet"]),
    (("eval", "shape"), ["--bodies", "2", "--quiet"]),
    (("eval", "speed"), ["--max-clips", "1", "--shape-clips", "0", "--quiet"]),
    (("eval", "codec-actions"), ["--per-action", "1"]),
    (("eval", "shape-words"), ["--texts", "3"]),
    (("demo",), ["--frames", "2"]),
    (("blend",), ["--resolution", "96", "96"]),
    (("render",), ["--frames", "2", "--resolution", "96", "96"]),
]


def joined_lines(text: str) -> list[str]:
    """The text's lines, stripped, a line ending in a backslash joined with the next (as a shell does)."""
    return [ln.strip() for ln in re.sub(r"\\\n\s*", "", text).splitlines()]


def page_examples(path: Path = PAGE) -> list[str]:
    """The `python -m shapemove ...` commands of the page's ```sh blocks, in order."""
    blocks = re.findall(r"```sh\n(.*?)```", path.read_text(encoding="utf-8"), re.S)
    return [ln for b in blocks for ln in joined_lines(b) if ln.startswith(PREFIX)]


def argv_of(line: str, mocap) -> list[str]:
    argv = shlex.split(line)[3:]
    argv = [str(mocap) if a == "../shared/data/*.tar.xz" else a for a in argv]
    for head, extra in FAST:
        if tuple(argv[:len(head)]) == head:
            argv += extra
    return argv


def test_every_command_has_an_example_on_the_page():
    from shapemove.cli import COMMANDS

    used = {shlex.split(ln)[3] for ln in page_examples()}
    assert set(COMMANDS) <= used, sorted(set(COMMANDS) - used)


def test_examples_elsewhere_are_the_pages():
    """The README's and the other pages' examples are copies of the tested ones (a synopsis with
    `[--option]` or a trailing `...` is not an example)."""
    tested = set(page_examples())
    for md in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for ln in joined_lines(md.read_text(encoding="utf-8")):
            ln = ln.lstrip("$ ").strip()
            if ln.startswith(PREFIX) and not ln.endswith("...") and " [--" not in ln:  # not a synopsis
                cmd = ln.split("  #")[0].strip()
                assert cmd in tested, f"{md.name}: {cmd!r} is not an example of docs/command-line.md"


def test_help_examples_are_the_pages():
    from shapemove.cli import EXAMPLES

    tested = set(page_examples())
    for name, example in EXAMPLES.items():
        assert example in tested, f"`{name} --help` shows {example!r}, which docs/command-line.md does not run"


@pytest.mark.slow
@pytest.mark.blender
def test_the_pages_examples_run(mocap_root, tmp_path):
    need_module("bpy", "the scene examples need the bpy module (pip install bpy==5.0.1)")
    examples = [{"line": ln, "argv": argv_of(ln, mocap_root)} for ln in page_examples()]
    plan, result = tmp_path / "plan.json", tmp_path / "result.json"
    work = tmp_path / "work"
    work.mkdir()
    plan.write_text(json.dumps({"cwd": str(work), "examples": examples}))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, str(ROOT / "tests" / "docs_examples_run.py"), str(plan), str(result)],
                          cwd=work, env=env, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    done = json.loads(result.read_text())
    assert len(done) == len(examples)
    failed = [f"{r['line']}\n  exit {r['rc']}\n{r['error'] or r['stdout']}" for r in done if r["rc"] != 0]
    assert not failed, "\n".join(failed) + "\n" + proc.stderr[-2000:]
    for name in ("wave.npz", "wave.blend", "wave.png", "out/kick/shapemove.blend", "tall_walk.npz", "hero_wave.blend",
                 "runs/t5", "out/eval_recon.json", "out/eval_shape.json"):
        assert (work / name).exists(), name


# pages another change is writing; a link to them may wait for it (nothing else may dangle)
PENDING: set[str] = set()


def _anchors(md: Path) -> set[str]:
    """GitHub's anchors of the page's headings."""
    heads = [ln.lstrip("#").strip().lower() for ln in md.read_text(encoding="utf-8").splitlines() if ln.startswith("#")]
    return {re.sub(r"[^\w\- ]", "", h).replace(" ", "-") for h in heads}


def test_links_between_the_pages_resolve():
    """Every relative link of the README and the manual names a file that exists, and a heading of it."""
    bad = []
    for md in [ROOT / "README.md", ROOT / "DEVELOPERS.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for link in re.findall(r"\]\(([^)\s]+)\)", md.read_text(encoding="utf-8")):
            if re.match(r"[a-z]+:", link):
                continue
            path, _, anchor = link.partition("#")
            target = (md.parent / path) if path else md
            if not target.exists():
                if target.name not in PENDING:
                    bad.append(f"{md.name}: {link} (no such file)")
            elif anchor and target.suffix == ".md" and anchor not in _anchors(target):
                bad.append(f"{md.name}: {link} (no such heading)")
    assert not bad, "\n".join(bad)
