"""The panel says what a model folder without ``tma/tma.pt`` loses (issue 28): the generate job's
``model_warnings`` are drawn under the rig, and are not mistaken for a prompt far from the training
data. Real bpy: the operator's callback builds the rig, the panel's real ``draw`` is recorded."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.generation.model_bundle import part_warnings
from shapemove.core.scene.motion_file import make_motion, save_motion

bpy = pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
from panel_layout import drawn  # noqa: E402  (the recording layout; the add-on fixture is conftest's)

pytestmark = pytest.mark.blender


def test_panel_shows_what_the_model_lacks(addon, openbody, tmp_path):
    from shapemove.shapemove_addon import operators, panels

    T = 12
    transl = np.stack([0.02 * np.arange(T), np.zeros(T), np.zeros(T)], -1)
    save_motion(tmp_path / "m.npz", make_motion(openbody, np.zeros((T, 24, 3)), transl, np.zeros(10), fps=20))
    (w,) = part_warnings(tmp_path / "no_model")  # a folder without tma/tma.pt
    rig = operators.on_generated("Walker", {"result": {"path": str(tmp_path / "m.npz"), "warnings": [w],
                                                      "model_warnings": [w], "nearest_actions": ["walk"]}})
    shown = drawn(panels.SHAPEMOVE_PT_generate, bpy.context)
    assert w in shown and "best-of-N picking is off" in w
    assert not any(s.startswith("Prompt unlike") for s in shown)  # the prompt was fine
