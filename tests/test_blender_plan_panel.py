"""The plan under the prompt in the Generate panel (issue 54): Read Plan shows each segment's
fields, the user changes them, Generate sends the edited plan, the worker's generate job makes the
motion from it, and its answer shows the plan it was made from, to change and generate again.
Real bpy in this process; the job runs in this process with the embedded default model, as the
worker runs it."""
from __future__ import annotations

import json

import pytest
from panel_layout import drawn

bpy = pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
pytestmark = pytest.mark.blender


def _run_job(params):
    from shapemove.core.worker.jobs_shapemove import generate

    return generate(params, lambda *_: None, lambda: False)


def test_the_plan_is_shown_edited_and_generated_from(addon, tmp_path, monkeypatch):
    from shapemove.shapemove_addon import job_submit, operators, panels, paths

    s = bpy.context.scene.shapemove
    s.prompt = "a man walks 2 metres forward, then waves"
    assert bpy.ops.shapemove.read_plan() == {"FINISHED"}
    assert [(i.text, i.action, i.distance) for i in s.plan_segments] == [
        ("a man walks 2 metres forward", "walk", 2.0), ("a man waves", "wave", 0.0)]
    log = drawn(panels.SHAPEMOVE_PT_generate, bpy.context)
    assert "Segment 2 of 2" in log and log.count("prop:distance") == 2 and "op:shapemove.read_plan" in log

    s.plan_segments[0].seconds, s.plan_segments[1].seconds = 1.0, 1.2   # the user's changes
    s.plan_segments[1].action = "jump"
    sent = []
    monkeypatch.setattr(job_submit, "submit_job", lambda op, params, **kw: sent.append((params, kw["on_result"])))
    monkeypatch.setattr(paths, "new_motion_path", lambda label: tmp_path / f"{len(sent)}.npz")
    assert bpy.ops.shapemove.generate() == {"FINISHED"}
    params, on_result = sent[-1]
    plan = json.loads(params["plan"])
    assert [seg["seconds"] for seg in plan["segments"]] == [1.0, 1.2]
    assert plan["segments"][1]["understood"]["actions"] == ["jump"]

    params["candidates"] = 1
    result = _run_job(params)
    rig = on_result({"result": result})
    assert rig is not None
    made = json.loads(result["plan"])
    assert [seg["text"] for seg in made["segments"]] == ["a man walks 2 metres forward", "a man jumps"]
    assert result["frames"] == pytest.approx(44, abs=2)   # 1.0 + 1.2 s at 20 fps
    assert [i.action for i in s.plan_segments] == ["walk", "jump"]   # shown as made, to change again

    import numpy as np

    from shapemove.core.generation.track import headings
    from shapemove.core.scene.motion_file import load_motion

    s.plan_segments[0].course, s.plan_segments[0].distance = "walk in a circle", 0.0   # the walk goes round
    assert bpy.ops.shapemove.generate() == {"FINISHED"}
    circled = _run_job({**sent[-1][0], "candidates": 1})
    assert json.loads(circled["plan"])["segments"][0]["understood"]["course"] == "walk in a circle"

    def turned(path) -> float:   # radians the first segment turns
        m = load_motion(path)
        a, b = m.segment_bounds[0]
        h = np.unwrap(headings(m.joints))
        return abs(float(h[b - 1] - h[a]))

    assert turned(circled["path"]) > 3.0 > 1.5 > turned(result["path"])

    s.plan_segments[0].count = 2   # no jump, hop or squat in a walk: the job names the field
    monkeypatch.setattr(operators, "on_generated", lambda *a, **k: None)
    assert bpy.ops.shapemove.generate() == {"FINISHED"}
    from shapemove.core.errors import ShapeMoveError

    with pytest.raises(ShapeMoveError, match=r"segments\[0\]\.understood\.count"):
        _run_job(sent[-1][0])

    s.prompt = "a person sits down"   # another prompt: the old plan is left aside
    assert bpy.ops.shapemove.generate() == {"FINISHED"}
    assert "plan" not in sent[-1][0]
    assert bpy.ops.shapemove.clear_plan() == {"FINISHED"} and len(s.plan_segments) == 0


def test_the_panel_offers_every_course_the_plan_takes(addon):
    import bpy

    from shapemove.core.plan.vocabulary import COURSE_KINDS

    seg = bpy.context.scene.shapemove.plan_segments.add()
    assert set(COURSE_KINDS) <= {item.identifier for item in seg.bl_rna.properties["course"].enum_items}


def test_a_course_segment_shows_the_time_to_go_once_round(addon):
    """Read Plan gives a course's segment the time to go once round at the active model's typical
    walk (2 pi / (0.9 x 1.194 m/s) = 5.85 s), as generating makes it, without torch in the panel's
    process (``course_shapes``)."""
    import subprocess
    import sys

    s = bpy.context.scene.shapemove
    s.prompt = "a man walks a loop around the tree, then waves"
    assert bpy.ops.shapemove.read_plan() == {"FINISHED"}
    assert [round(i.seconds, 2) for i in s.plan_segments] == [5.85, 3.0]
    code = ("import sys; sys.modules['torch'] = None\n"
            "from shapemove.core.generation.course_shapes import model_course_seconds\n"
            "from shapemove.core.plan.words import read_words\n"
            "print(round(model_course_seconds()(read_words('a man walks in a circle')), 2))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "5.85", out.stderr


def test_the_manner_is_a_field_and_generating_plays_the_takes_done_so(addon, tmp_path, monkeypatch):
    """"a man walks proudly, then bows": the first segment's manner is shown (proud), the user
    makes the bow a happy one and the walk plain; the job plays Bandai's happy bow and a plain walk."""
    from shapemove.shapemove_addon import job_submit, panels, paths

    s = bpy.context.scene.shapemove
    s.prompt = "a man walks proudly, then bows"
    assert bpy.ops.shapemove.read_plan() == {"FINISHED"}
    assert [(i.action, i.manner) for i in s.plan_segments] == [("walk", "proud"), ("bow", "NONE")]
    assert drawn(panels.SHAPEMOVE_PT_generate, bpy.context).count("prop:manner") == 2
    s.plan_segments[0].manner, s.plan_segments[1].manner = "NONE", "happy"
    sent = []
    monkeypatch.setattr(job_submit, "submit_job", lambda op, params, **kw: sent.append((params, kw["on_result"])))
    monkeypatch.setattr(paths, "new_motion_path", lambda label: tmp_path / f"{len(sent)}.npz")
    assert bpy.ops.shapemove.generate() == {"FINISHED"}
    plan = json.loads(sent[-1][0]["plan"])
    assert "manner" not in plan["segments"][0]["understood"] and plan["segments"][1]["understood"]["manner"] == "happy"
    result = _run_job({**sent[-1][0], "candidates": 1})
    assert "bow_happy" in result["provenance"] and "walk_proud" not in result["provenance"], result["provenance"]
