"""The panel says when Retarget moved a take by its own rotations because the model's codes miss it
(``generation/retarget.py``'s fallback): the job's warnings are kept on the rig and drawn under it.
Real bpy: the retarget operator's own job callback builds the rig; the panel's real ``draw`` is
recorded. The job itself is run for real in tests/test_code_search.py."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.scene.motion_file import make_motion, save_motion

bpy = pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
from test_blender_panel_feedback import _draw, addon  # noqa: E402,F401  (the recording layout, the add-on fixture)

pytestmark = pytest.mark.blender


def test_panel_says_a_take_was_moved_by_its_rotations(addon, openbody, tmp_path, monkeypatch):  # noqa: F811
    from shapemove.shapemove_addon import job_submit, operators, panels
    from shapemove.shapemove_addon.rig_state import RETARGET_NOTE_KEY

    T = 12
    transl = np.stack([0.02 * np.arange(T), np.zeros(T), np.zeros(T)], -1)
    save_motion(tmp_path / "m.npz", make_motion(openbody, np.zeros((T, 24, 3)), transl, np.zeros(10), fps=20))
    jobs = []
    monkeypatch.setattr(job_submit, "submit_job", lambda op, params, **kw: jobs.append((op, params, kw)) or "j1")
    operators._retarget_job(bpy.context, str(tmp_path / "kick.bvh"), None, "Kicker")
    (op, params, kw), = jobs
    assert op == "retarget" and params["source"].endswith("kick.bvh") and "betas" not in params
    note = "the SA-VAE's codes miss this take by 157 mm in its worst second (more than 100 mm): ..."
    kw["on_result"]({"result": {"path": str(tmp_path / "m.npz"), "method": "planted", "warnings": [note]}})
    rig = operators.active_rig(bpy.context)
    assert rig is not None and list(rig[RETARGET_NOTE_KEY]) == [note]
    assert note in _draw(panels.SHAPEMOVE_PT_generate, bpy.context)
    # a take the codes carry leaves no note
    kw["on_result"]({"result": {"path": str(tmp_path / "m.npz"), "method": "savae", "warnings": []}})
    rig = operators.active_rig(bpy.context)
    assert RETARGET_NOTE_KEY not in rig and not any("SA-VAE" in s for s in _draw(panels.SHAPEMOVE_PT_generate,
                                                                                 bpy.context))
