"""After a generation the Generate panel shows the motion's physics figures and the body's
measurements. Real bpy in this process: the add-on is registered, the generate job's answer is
made by the worker's own helpers (core/eval physics, core/body measurements) for a real motion
file and handed to the operator's callback, and the panel's real ``draw`` is run on a layout that
records what it draws."""
from __future__ import annotations

import numpy as np
import pytest

from panel_layout import drawn

from shapemove.core.scene.motion_file import make_motion, save_motion

bpy = pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
pytestmark = pytest.mark.blender


def test_generate_panel_shows_physics_and_measurements(addon, openbody, tmp_path):
    from shapemove.core.worker.jobs_shapemove import _measurements, _physics
    from shapemove.shapemove_addon import operators, panels

    rng = np.random.default_rng(2)
    T = 30
    t = np.arange(T)[:, None, None]
    poses = rng.normal(0, 0.3, (1, 24, 3)) * np.sin(0.2 * t + rng.uniform(0, 6, (1, 24, 3)))
    transl = np.stack([0.02 * np.arange(T), np.full(T, 0.05), 0.03 * np.arange(T)], -1)  # floats 5 cm up
    betas = rng.normal(0, 0.8, 10).astype(np.float32)
    motion = make_motion(openbody, poses, transl, betas, fps=20, prompt="a test motion")
    save_motion(tmp_path / "m.npz", motion)
    physics, measurements = _physics(openbody, motion), _measurements(openbody, betas)
    assert set(physics) == {"penetrate_cm", "float_cm", "skate_pct", "dyn_stable_pct"}
    assert physics["float_cm"] > 3.0  # it does float: the figures are the motion's own
    assert set(measurements) >= {"height_cm", "chest_cm", "waist_cm", "hip_cm"}

    before = drawn(panels.SHAPEMOVE_PT_generate, bpy.context)
    assert not any(s.startswith(("Penetrate", "Height")) for s in before)  # nothing generated yet

    rig = operators.on_generated("Walker", {"result": {"path": str(tmp_path / "m.npz"), "measurements": measurements,
                                                      "physics": physics}})
    assert rig is not None and bpy.context.view_layer.objects.active == rig
    assert dict(rig[operators.PHYSICS_KEY]) == pytest.approx(physics)
    shown = drawn(panels.SHAPEMOVE_PT_generate, bpy.context)
    assert f"Penetrate: {physics['penetrate_cm']:.2f} cm" in shown
    assert f"Float: {physics['float_cm']:.2f} cm" in shown
    assert f"Skate: {physics['skate_pct']:.1f} %" in shown
    assert f"Stability: {physics['dyn_stable_pct']:.0f} %" in shown
    for prop, label in (("height_cm", "Height"), ("chest_cm", "Chest"), ("waist_cm", "Waist"), ("hip_cm", "Hips")):
        assert f"{label}: {measurements[prop]:.1f} cm" in shown
    assert f"Mass: {measurements['mass_kg']:.1f} kg" in shown and f"BMI: {measurements['bmi']:.1f}" in shown
    assert rig.name in shown

    # a cancelled job builds nothing
    n = len(bpy.data.objects)
    assert operators.on_generated("X", {"cancelled": True}) is None and len(bpy.data.objects) == n
