"""The panel says when a take was played from its own rotations because the model's codes miss it:
Retarget's fallback (``generation/retarget.py``) and a Library clip kept for a prompt
(``generation/library_takes.py``, the Generate panel's "Use Library motions"). The jobs' notes are
kept on the rig and drawn under it. Real bpy: the operators' own job callbacks build the rig; the
panel's real ``draw`` is recorded. The jobs themselves run for real in tests/test_code_search.py
and tests/test_retrieved_candidates.py."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.scene.motion_file import make_motion, save_motion

bpy = pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
from panel_layout import drawn  # noqa: E402  (the recording layout; the add-on fixture is conftest's)

pytestmark = pytest.mark.blender


def test_panel_says_a_take_was_moved_by_its_rotations(addon, openbody, tmp_path, monkeypatch):
    from shapemove.shapemove_addon import job_submit, operators, panels, redecode
    from shapemove.shapemove_addon.rig_state import TAKE_NOTES_KEY

    T = 12
    transl = np.stack([0.02 * np.arange(T), np.zeros(T), np.zeros(T)], -1)
    contacts = np.ones((T, 4), np.uint8)     # a take played by its own rotations: measured contacts, no tokens
    save_motion(tmp_path / "m.npz", make_motion(openbody, np.zeros((T, 24, 3)), transl, np.zeros(10), fps=20,
                                                contacts=contacts, contacts_measured=True))
    save_motion(tmp_path / "plain.npz", make_motion(openbody, np.zeros((T, 24, 3)), transl, np.zeros(10), fps=20))
    jobs = []
    monkeypatch.setattr(job_submit, "submit_job", lambda op, params, **kw: jobs.append((op, params, kw)) or "j1")
    operators._retarget_job(bpy.context, str(tmp_path / "kick.bvh"), None, "Kicker")
    (op, params, kw), = jobs
    assert op == "retarget" and params["source"].endswith("kick.bvh") and "betas" not in params
    note = "the SA-VAE's codes miss this take by 157 mm in its worst second (more than 100 mm): ..."
    kw["on_result"]({"result": {"path": str(tmp_path / "m.npz"), "method": "planted", "notes": [note]}})
    rig = operators.active_rig(bpy.context)
    assert rig is not None and list(rig[TAKE_NOTES_KEY]) == [note]
    assert note in drawn(panels.SHAPEMOVE_PT_generate, bpy.context)
    assert redecode.wants_redecode(rig)     # a shape change plants it again (the redecode job: retarget.replant)
    # a take the codes carry leaves no note; a motion with neither tokens nor measured contacts is not remade
    kw["on_result"]({"result": {"path": str(tmp_path / "plain.npz"), "method": "savae", "notes": []}})
    rig = operators.active_rig(bpy.context)
    assert TAKE_NOTES_KEY not in rig and not any("SA-VAE" in s for s in drawn(panels.SHAPEMOVE_PT_generate,
                                                                                 bpy.context))
    assert not redecode.wants_redecode(rig)


def _asks_for_the_library(run, op: str, jobs: list, tmp_path) -> None:
    """The operator ``run`` sends no "library" until Use Library motions is on, then the Library
    folder; a folder that is gone is refused by name."""
    s = bpy.context.scene.shapemove
    s.prompt = "someone kicks high in front of them"
    lib = tmp_path / "library"
    lib.mkdir()
    s.library_folder, s.use_library = str(lib), False
    assert "FINISHED" in run()
    assert jobs[-1][0] == op and "library" not in jobs[-1][1]          # off by default
    s.use_library = True
    assert "FINISHED" in run()
    assert jobs[-1][1]["library"] == str(lib)
    s.library_folder = str(tmp_path / "nowhere")
    with pytest.raises(RuntimeError, match="library folder not found"):
        run()


def _motion_file(openbody, tmp_path):
    T = 12
    transl = np.stack([0.02 * np.arange(T), np.zeros(T), np.zeros(T)], -1)
    save_motion(tmp_path / "m.npz", make_motion(openbody, np.zeros((T, 24, 3)), transl, np.zeros(10), fps=20))
    return str(tmp_path / "m.npz")


NOTE = "played as captured from your library (kick.bvh): its codes miss it by 253 mm in its worst second"


def test_generate_uses_the_library_when_asked_and_notes_a_captured_take(addon, openbody, tmp_path,
                                                                         monkeypatch):
    from shapemove.shapemove_addon import job_submit, operators, panels
    from shapemove.shapemove_addon.rig_state import TAKE_NOTES_KEY

    jobs = []
    monkeypatch.setattr(job_submit, "submit_job", lambda op, params, **kw: jobs.append((op, params, kw)) or "j1")
    _asks_for_the_library(bpy.ops.shapemove.generate, "generate", jobs, tmp_path)
    rig = operators.on_generated("Kicker", {"result": {"path": _motion_file(openbody, tmp_path), "warnings": [],
                                                      "notes": [NOTE]}})
    assert list(rig[TAKE_NOTES_KEY]) == [NOTE]
    shown = drawn(panels.SHAPEMOVE_PT_generate, bpy.context)
    assert NOTE in shown and not any(line.startswith("Prompt unlike") for line in shown)


def test_generate_animated_uses_the_library_and_keeps_the_note(addon, openbody, tmp_path, monkeypatch):
    """Loop, root motion, path and speed ("Generate Animated") take the Library as Generate does, and
    the rig they build keeps the job's note."""
    from shapemove.shapemove_addon import job_submit, operators, panels
    from shapemove.shapemove_addon.rig_state import TAKE_NOTES_KEY

    jobs = []
    monkeypatch.setattr(job_submit, "submit_job", lambda op, params, **kw: jobs.append((op, params, kw)) or "j1")
    bpy.context.scene.shapemove_animation.loop = True
    _asks_for_the_library(bpy.ops.shapemove.animate, "animate", jobs, tmp_path)
    assert jobs[-1][1]["loop"]
    jobs[-1][2]["on_result"]({"result": {"path": _motion_file(openbody, tmp_path), "warnings": [], "notes": [NOTE]}})
    rig = operators.active_rig(bpy.context)
    assert rig is not None and list(rig[TAKE_NOTES_KEY]) == [NOTE]
    assert NOTE in drawn(panels.SHAPEMOVE_PT_generate, bpy.context)
