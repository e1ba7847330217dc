"""No traceback for any valid prompt or file (issue 54): a table of prompts of every kind the
generator reads (courses, distances, counts, stops, paces, sides, two things at once, turns, in
place, plain actions, sequences in one prompt), with and without --loop / --in-place / --path /
--speed, through the entry points of `generate`, `sequence`, `retarget` and `blend` (on the
project's own motion files), `render` (a batch of every kind, a line that cannot be made reported)
and `demo`, with the embedded default model: each exits 0 with no "Traceback" in its output; and
through the panel's operators (Read Plan on every prompt of the table; Generate, Generate Animated,
Generate Timeline, Regenerate Strip with their jobs run in this process as the worker runs them).
1 to 2 s motions and one candidate keep the table fast; the commands reuse the process's loaded
model (generation/loaded_generator.py) as they do inside the worker."""
from __future__ import annotations

import json

import numpy as np
import pytest

from shapemove.cli import main
from shapemove.core.scene.motion_file import load_motion

FAST = ["--candidates", "1", "--seed", "1"]
LOOP, IN_PLACE, PATH, SPEED = ["--loop"], ["--in-place"], ["--path", "{path}"], ["--speed", "1.5"]

TABLE = [   # (prompt, seconds, options)
    # courses
    ("a man walks in a circle", 2, []), ("a man walks in a circle", 2, LOOP), ("a man walks in a figure eight", 2, []),
    ("a woman walks in a figure eight", 2, IN_PLACE), ("someone paces back and forth", 2, []),
    ("a person walks to and fro", 2, SPEED), ("a man walks in a zigzag", 2, PATH),
    ("she walks diagonally to the right", 1, []), ("a man jogs around in a circle clockwise", 2, LOOP),
    # distances
    ("a man walks 3 metres forward", 1, []), ("she runs ten meters and stops", 1, IN_PLACE),
    ("a person jogs 20 feet", 1, LOOP), ("a man walks 2 m forward, waving", 1, []),
    # counts
    ("a person jumps twice", 1, []), ("a man does three squats", 1, SPEED), ("someone hops three times", 1, LOOP),
    ("she takes three steps forward", 1, []), ("he takes a step back", 1, IN_PLACE),
    # stops
    ("a man takes three steps forward and stops", 1, []), ("a person walks forward and then stops", 1, LOOP),
    ("she jogs, then comes to a stop", 1, PATH), ("a person stands still", 1, []),
    # paces and speeds
    ("a woman walks slowly", 1, []), ("a woman walks slowly", 1, LOOP), ("a man runs quickly", 1, SPEED),
    ("an old man walks slowly", 1, PATH), ("a person sprints forward", 1, IN_PLACE), ("a man walks briskly", 1, []),
    # sides
    ("someone kicks with the left leg", 1, []), ("a person waves with the right hand", 1, LOOP),
    ("he punches with his left fist", 1, SPEED), ("she raises her left arm", 1, IN_PLACE),
    # two things at once
    ("a person jogs forward and waves", 1, []), ("a woman jogs along, waving her left hand", 1, LOOP),
    ("a man walks and waves", 1, PATH), ("a woman jogs in a circle and waves", 2, []),
    ("someone walks forward while clapping", 1, SPEED), ("a man marches and punches", 1, IN_PLACE),
    # turns
    ("someone turns around", 1, []), ("someone turns around", 1, LOOP), ("a person turns left", 1, PATH),
    ("a dancer spins", 1, SPEED), ("a man walks forward and turns to the right", 2, IN_PLACE),
    # in place
    ("a person jogs in place", 1, []), ("a person jogs in place", 1, LOOP), ("a man marches on the spot", 1, SPEED),
    ("a woman walks in place", 1, IN_PLACE),
    # plain actions
    ("a person walks forward", 1, PATH), ("a person sits down", 1, []), ("a man throws a ball", 1, LOOP),
    ("a man cooks pasta in a kitchen", 1, []), ("someone crawls forward", 1, SPEED),
    # sequences in one prompt
    ("a person walks forward, then sits down", 2, []), ("after waving, she jogs", 2, LOOP),
    ("a man jogs and then waves", 2, IN_PLACE), ("before sitting down he waves", 2, SPEED),
    ("first a person walks forward, then turns around, then sits down", 2, []),
    ("a woman walks in a circle followed by jumping twice", 2, []), ("a person walks forward, then turns around", 2, PATH),
    ("she jogs in place, then walks 2 metres forward and stops", 2, []),
    ("a man kicks with the left leg and then punches with the right hand", 2, LOOP),
    # a gait to one side, a list of steps, a way alone after "then", "follows it with", a course's segment
    ("a man runs to the left", 1, []), ("she jogs off to her right", 1, LOOP), ("a man runs to the left", 1, PATH),
    ("a woman walks to the right, waving", 1, IN_PLACE), ("a man runs to the left then to the right", 2, SPEED),
    ("she walks ahead, spins around, then waves", 2, []), ("a man jumps and follows it with a bow", 2, LOOP),
    ("after a long walk she sits down", 2, []), ("a man walks a loop around the tree, then waves", 2, IN_PLACE),
    ("a thief tiptoes along", 1, LOOP),
    # "once" and "having" order, a person of any noun says every segment, a pick-up, a body in a timeline
    ("once she has waved, she runs off", 2, SPEED), ("having bowed, the actor walks away", 2, LOOP),
    ("the boxer punches, then kicks", 2, []), ("a man picks up a box from the floor", 1, IN_PLACE),
    ("a short, stocky woman walks forward, then sits down", 2, PATH),
    # manners: a take done so, none done so (said), a manner in a sequence, a sidestep that goes aside
    ("a man walks proudly", 1, LOOP), ("a tired woman runs", 1, PATH), ("a man sits down proudly", 1, IN_PLACE),
    ("a man bows happily, then walks away sadly", 2, SPEED), ("before crouching down, she looks around", 2, []),
    ("a man steps to the side", 1, LOOP),
]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("no_traceback")
    (d / "path.json").write_text(json.dumps([[0, 0], [0, 1.0], [0.6, 2.0]]))
    return d


def _run(argv, capsys):
    code = main(argv)
    out = capsys.readouterr()
    text = out.out + out.err
    assert code == 0 and "Traceback" not in text, f"{argv}: exit {code}\n{text[-2000:]}"
    return out.out


def test_the_table_is_every_kind_at_least_60_prompts():
    assert len(TABLE) >= 60
    assert {tuple(o) for _, _, o in TABLE} == {(), tuple(LOOP), tuple(IN_PLACE), tuple(PATH), tuple(SPEED)}


@pytest.mark.parametrize("i", range(len(TABLE)), ids=[f"{p[:28]}{' ' + o[0] if o else ''}" for p, _, o in TABLE])
def test_generate(folder, capsys, i):
    prompt, seconds, options = TABLE[i]
    out = folder / f"g{i:02d}.npz"
    opts = [o.replace("{path}", str(folder / "path.json")) for o in options]
    said = _run(["generate", "--prompt", prompt, "--seconds", str(seconds), *FAST, *opts, "--out", str(out)], capsys)
    m = load_motion(out)
    assert m.num_frames > 0 and np.isfinite(m.joints).all()
    assert "understood" in said
    if options == LOOP and ("circle" in prompt or "turns around" in prompt):   # which request won, said
        assert "note: --loop won over" in said


def test_sequence(folder, capsys):
    for prompts in (["a person walks in a circle", "a person turns around"], ["someone jogs in place", "a man waves"],
                    ["a person walks 2 metres forward and stops", "she sits down"]):
        argv = ["sequence", *[a for p in prompts for a in ("--prompt", p, "--seconds", "1")], *FAST[:2],
                "--out", str(folder / "seq.npz")]
        _run(argv, capsys)
    _run(["sequence", "--prompt", "a man walks forward", "--seconds", "1", "--prompt", "he turns around", "--seconds", "1",
          "--in-place", "--out", str(folder / "seq_in_place.npz")], capsys)


@pytest.fixture(scope="module")
def own_files(folder):
    """The project's own motion files of every make: a course, a loop, a timeline, one held in place."""
    made = {}
    for name, argv in (("course", ["--prompt", "a man walks in a figure eight", "--seconds", "2"]),
                       ("loop", ["--prompt", "a person walks forward", "--seconds", "2", "--loop"]),
                       ("timeline", ["--prompt", "a person walks forward, then sits down", "--seconds", "2"]),
                       ("held", ["--prompt", "a person jogs forward", "--seconds", "2", "--in-place"])):
        made[name] = folder / f"own_{name}.npz"
        assert main(["generate", *argv, *FAST, "--out", str(made[name])]) == 0
    return made


def test_retarget_reads_our_own_motion_files(folder, own_files, capsys):
    made = own_files
    for name, path in made.items():
        out = folder / f"retargeted_{name}.npz"
        said = _run(["retarget", "--motion", str(path), "--betas", "1.5,-1", "--no-search", "--out", str(out)], capsys)
        m = load_motion(out)
        assert m.betas[:2] == pytest.approx([1.5, -1.0]) and m.num_frames >= 24, said
        assert abs(m.num_frames - load_motion(path).num_frames) <= 4   # the whole take, in whole codes
    _run(["retarget", "--motion", str(made["course"]), "--shape-text", "a short, slim woman", "--naive",
          "--out", str(folder / "naive.npz")], capsys)


@pytest.mark.blender
def test_demo_on_motions_without_tokens(folder, capsys):
    from conftest import need_module

    need_module("bpy", "the demo builds its scene with the bpy module")
    for prompt in ("a man walks in a figure eight", "someone turns around"):
        said = _run(["demo", "--prompt", prompt, "--seconds", "1", "--frames", "1", "--out", str(folder / "demo")],
                    capsys)
        assert "0 tokens" in said and "understood" in said


@pytest.mark.blender
def test_blend_builds_our_own_motion_files(folder, own_files, capsys):
    from conftest import need_module

    need_module("bpy", "blend builds its scene with the bpy module")
    for name, path in own_files.items():
        out = folder / f"own_{name}.blend"
        _run(["blend", "--motion", str(path), "--out", str(out)], capsys)
        assert out.stat().st_size > 0


@pytest.mark.blender
def test_render_a_batch_of_every_kind(folder, capsys):
    from conftest import need_module

    need_module("bpy", "render builds its scenes with the bpy module")
    lines = [{"prompt": "a man walks in a circle", "seconds": 1}, {"prompt": "someone turns around", "seconds": 1, "loop": True},
             {"prompt": "a person walks forward, then sits down", "seconds": 1.5},
             {"prompt": "she runs ten meters and stops", "seconds": 1, "in_place": True},
             {"prompt": "a woman jogs along, waving her left hand", "seconds": 1, "speed": 1.5},
             {"prompt": "a person walks forward, then sits down, then waves", "seconds": 0.5}]   # too short: reported
    (folder / "batch.jsonl").write_text("\n".join(json.dumps(x) for x in lines) + "\n")
    said = _run(["render", "--prompts", str(folder / "batch.jsonl"), "--out", str(folder / "rendered"),
                 "--frames", "1", "--resolution", "48", "48"], capsys)
    assert "rendered 5 of 6 prompts" in said and "under the 0.4 s one needs" in said
    assert len(list((folder / "rendered").glob("*.blend"))) == 5


@pytest.mark.blender
def test_the_panels_operators(folder, monkeypatch):
    """Read Plan on every prompt of the table; Generate (from the plan read, and after the prompt
    changed), Generate Animated, Generate Timeline and Regenerate Strip, their jobs run here."""
    from conftest import need_module

    need_module("bpy", "the panel's operators need the bpy module")
    import bpy

    import shapemove
    from shapemove.core.worker.ops import default_jobs
    from shapemove.shapemove_addon import job_submit, paths

    jobs = default_jobs()
    answered = []

    def submit(op, params, *, kind=None, label=None, on_result=None, on_error=None, on_progress=None):
        params = {**params, **({"candidates": 1} if op == "generate" else {})}
        result = jobs[op](params, lambda *_: None, lambda: False)
        answered.append((op, on_result({"id": len(answered), "result": result}) if on_result else None))
        return str(len(answered))

    bpy.ops.wm.read_factory_settings(use_empty=True)
    shapemove.register()
    try:
        monkeypatch.setattr(job_submit, "submit_job", submit)
        monkeypatch.setattr(paths, "new_motion_path", lambda label: folder / f"panel_{len(answered):02d}.npz")
        s, a = bpy.context.scene.shapemove, bpy.context.scene.shapemove_animation
        s.use_seconds, s.seconds = True, 1.0
        for prompt, _, _ in TABLE:
            s.prompt = prompt
            assert bpy.ops.shapemove.read_plan() == {"FINISHED"} and len(s.plan_segments) >= 1
        for prompt in ("a man walks in a figure eight", "someone turns around", "a person jogs in place",
                       "she takes three steps forward", "a person walks forward, then sits down"):
            s.prompt = prompt
            if "then" in prompt:
                s.seconds = 2.0
                bpy.ops.shapemove.read_plan()
            assert bpy.ops.shapemove.generate() == {"FINISHED"}
            assert answered[-1][1] is not None, prompt    # the rig was built
        s.prompt, s.seconds = "a person walks forward", 1.0   # a plan read, then the prompt changed
        assert bpy.ops.shapemove.generate() == {"FINISHED"} and answered[-1][1] is not None
        a.loop = True
        assert bpy.ops.shapemove.animate() == {"FINISHED"}
        a.loop = False
        for prompt in ("a person walks in a circle", "a man waves"):
            s.prompt = prompt
            bpy.ops.shapemove.timeline_add()
        a.timeline[0].seconds = a.timeline[1].seconds = 1.0
        assert bpy.ops.shapemove.sequence() == {"FINISHED"}
        assert bpy.ops.shapemove.regenerate_strip() == {"FINISHED"}
        assert [op for op, _ in answered] == ["generate"] * 6 + ["animate", "sequence", "sequence"]
    finally:
        shapemove.unregister()
        bpy.ops.wm.read_factory_settings(use_empty=True)
