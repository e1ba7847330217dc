"""Runs the manual's command-line examples one after the other in one process (not a test module;
tests/test_docs_examples.py starts it). One process: torch, bpy and the default model load once, so
the whole page runs in about a minute.

    python tests/docs_examples_run.py PLAN.json RESULT.json

PLAN: {"cwd": folder, "examples": [{"line": text, "argv": [...]}, ...]}. The folder gets what the
examples read that no earlier example writes (links to weights/ and configs/, prompts.txt, a path
s_curve.json, a BVH clip, a .blend with a Mixamo-named armature "Hero", a two-prompt paraphrase file). RESULT: one
{"line", "rc", "seconds", "error"} per example, written after each one (a crash leaves the ones so far).
"""
from __future__ import annotations

import io
import json
import os
import sys
import time
import traceback
from contextlib import redirect_stdout
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))


def walk_bvh(path: Path, frames: int = 60) -> None:
    """A Mixamo-named skeleton swinging its legs and arms while it moves forward (30 fps)."""
    import numpy as np

    from mocap_synth import bvh_text, mixamo_skeleton, still_motion

    names, parents, rest = mixamo_skeleton()
    m = still_motion(rest[0], len(names), frames)
    t = np.arange(frames) / 30.0
    m[:, 2] += 1.2 * t  # forward (+Z) at 1.2 m/s
    swing = 25 * np.sin(2 * np.pi * t)
    for name, sign in (("LeftUpLeg", 1), ("RightUpLeg", -1), ("LeftArm", -1), ("RightArm", 1)):
        j = names.index("mixamorig:" + name)
        m[:, 6 + 3 * (j - 1) + 1] = sign * swing  # X rotation (channels Z X Y)
    path.write_text(bvh_text(names, parents, rest, m))


def hero_blend(path: Path) -> None:
    """A .blend holding only a T-posed, Mixamo-named armature object "Hero"."""
    import bpy
    import numpy as np

    from mocap_synth import SMPL_REST
    from rig_builders import mixamo, posed_joints

    bpy.ops.wm.read_factory_settings(use_empty=True)
    arm = bpy.data.armatures.new("Hero")
    obj = bpy.data.objects.new("Hero", arm)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    for name, parent, head, tail, roll, deform in mixamo(posed_joints(SMPL_REST), np.random.default_rng(0)):
        eb = arm.edit_bones.new(name)
        eb.head, eb.tail, eb.roll, eb.use_deform = tuple(head), tuple(tail), roll, deform
        if parent:
            eb.parent = arm.edit_bones[parent]
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.wm.save_as_mainfile(filepath=str(path))


def prepare(cwd: Path) -> None:
    for name in ("weights", "configs"):
        if not (cwd / name).exists():
            (cwd / name).symlink_to(ROOT / name, target_is_directory=True)
    (cwd / "prompts.txt").write_text("a person walks forward\n")
    (cwd / "s_curve.json").write_text(json.dumps([[0, 0], [0.5, 1], [0, 2], [-0.5, 3], [0, 4]]))
    (cwd / "tiny_prompts.json").write_text(json.dumps({"prompts": [
        {"text": "a person walks forward", "action": "walk"}, {"text": "someone kicks", "action": "kick"}]}))
    walk_bvh(cwd / "walk.bvh")
    hero_blend(cwd / "hero.blend")


def main(plan_file: str, result_file: str) -> int:
    plan = json.loads(Path(plan_file).read_text())
    cwd = Path(plan["cwd"])
    os.chdir(cwd)
    prepare(cwd)
    from shapemove.cli import main as cli_main

    results = []
    for ex in plan["examples"]:
        t0, err, out = time.time(), "", io.StringIO()
        try:
            with redirect_stdout(out):
                rc = cli_main(list(ex["argv"]))
        except SystemExit as exc:  # argparse refusing an option
            rc = exc.code if isinstance(exc.code, int) else 2
        except Exception:  # noqa: BLE001  (reported, the next example still runs)
            rc, err = 1, traceback.format_exc()[-3000:]
        results.append({"line": ex["line"], "rc": rc, "seconds": round(time.time() - t0, 2), "error": err,
                        "stdout": out.getvalue()[-1500:]})
        Path(result_file).write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(*sys.argv[1:3]))
