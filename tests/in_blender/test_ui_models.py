"""The ShapeMove jobs that need trained models, inside real Blender, with the tiny models of the
``tiny_bundle`` fixture (started by tests/test_blender_ui.py through ``blender_inside.run``):
generate, re-decode after a shape change, library search and import, retarget of the active
armature's action, training that publishes a selectable model. Tests run in file order.
"""
from __future__ import annotations

import os

import numpy as np
import pytest
from ui_support import ADDON, CONFIG, MM, allow_torch, draw_panels, ext, install, job_messages, keyed_frames, \
    posed_heads, report_error, run_jobs

import bpy


@pytest.fixture(scope="module")
def torch():
    assert sorted(install()) == ["FINISHED"]
    torch = allow_torch()
    jobs, client = ext("shapemove_addon.jobs"), ext("core.worker.client")
    jobs.manager().set_runner(client.InProcessRunner())
    bpy.context.preferences.addons[ADDON].preferences.active_model = CONFIG["model_dir"]
    return torch


def _run(op, timeout=120.0):
    """Run an operator and its jobs; -> (operator result, finished, error messages, new objects)."""
    errors, restore = job_messages()
    before = set(bpy.data.objects)
    try:
        result = sorted(op())
        finished = run_jobs(timeout)
    finally:
        restore()
    return result, finished, errors, [o for o in bpy.data.objects if o not in before]


@pytest.fixture(scope="module")
def generated(torch):
    s = bpy.context.scene.shapemove
    s.prompt, s.use_seconds, s.seconds, s.seed = "a person walks forward", True, 2.0, 1
    result, finished, errors, new = _run(lambda: bpy.ops.shapemove.generate())
    assert result == ["FINISHED"] and finished and errors == []
    return new


def test_generate_builds_a_rig_from_the_job(generated):
    rig = next(o for o in generated if o.type == "ARMATURE")
    assert sorted(o.type for o in generated) == ["ARMATURE", "MESH"] and bpy.context.active_object == rig
    assert rig.get("shapemove_has_tokens") and keyed_frames(rig) == 40  # 2 s at 20 fps
    assert 120 < rig.shapemove.height_cm < 220  # the measurements came back with the motion
    # ... and the motion's physics figures (core/eval), for the Generate panel
    physics = dict(rig["shapemove_physics"])
    assert set(physics) <= {"penetrate_cm", "float_cm", "skate_pct", "dyn_stable_pct"} and "float_cm" in physics
    assert all(v >= 0 for v in physics.values())
    # written under the extension's user folder (bpy.utils.extension_path_user), not the package
    assert os.path.dirname(rig["shapemove_motion_file"]) == os.path.join(
        CONFIG["user_resources"], "extensions", ".user", "user_default", "shapemove", "data")


def test_shape_change_redecodes_the_motion(generated, torch):
    rig = next(o for o in generated if o.type == "ARMATURE")
    redecode, sync = ext("shapemove_addon.redecode"), ext("shapemove_addon.shape_sync")
    bpy.context.view_layer.objects.active = rig
    rig.shapemove.betas[1] = float(rig.shapemove.betas[1] + 1.5)  # the slider
    assert sorted(redecode.pending()) == [rig.name]
    _, finished, errors, _ = _run(lambda: redecode._fire() or ["FINISHED"])  # what the debounce timer does
    assert finished and errors == []
    path = rig.get("shapemove_redecoded_file")
    assert path
    mf = ext("core.scene.motion_file")
    m = mf.load_motion(path)
    # same tokens, decoded for the new body
    assert np.abs(m.betas - sync.current_betas(rig)).max() < 1e-4
    assert np.array_equal(m.tokens, mf.load_motion(rig["shapemove_motion_file"]).tokens)
    body = ext("core.scene.bodies").load_body(m.body_model)
    k = m.num_frames // 2
    bpy.context.scene.frame_set(1 + k)
    out = body.forward(torch.as_tensor(m.betas)[None], torch.as_tensor(m.poses[k:k + 1]), torch.as_tensor(m.transl[k:k + 1]))
    names = list(ext("core.body.skeleton").JOINT_NAMES)[:22]
    want = ext("core.scene.axes").points_to_z_up(out.joints[0, :22].numpy())
    assert np.abs(posed_heads(rig, names) - want).max() < MM  # the rig plays the re-decoded motion


def test_library_search_and_import(torch):
    s = bpy.context.scene.shapemove
    s.library_folder, s.library_query, s.library_top_k = CONFIG["dataset"], "a person walks", 3
    result, finished, errors, _ = _run(lambda: bpy.ops.shapemove.library_search())
    assert result == ["FINISHED"] and finished and errors == []
    scores = [i.score for i in s.library_results]
    assert len(scores) == 3 and scores == sorted(scores, reverse=True) and all(-1 <= x <= 1 for x in scores)
    assert [d["rows"] for d in draw_panels()["SHAPEMOVE_PT_library"] if d["kind"] == "list"] == [3]
    result, finished, errors, new = _run(lambda: bpy.ops.shapemove.library_import(index=0))
    assert result == ["FINISHED"] and finished and errors == []
    assert sorted(o.type for o in new) == ["ARMATURE", "MESH"]
    assert keyed_frames(next(o for o in new if o.type == "ARMATURE")) > 10


def test_retarget_the_active_armatures_action_onto_a_rig(generated):
    target = next(o for o in generated if o.type == "ARMATURE")
    bpy.ops.import_anim.bvh(filepath=CONFIG["bvh"], update_scene_fps=False, update_scene_duration=False)
    src = bpy.context.active_object
    assert src.type == "ARMATURE"
    for o in bpy.context.view_layer.objects:
        o.select_set(o == src)
    s = bpy.context.scene.shapemove
    s.retarget_source, s.retarget_target = "ACTION", target
    result, finished, errors, new = _run(lambda: bpy.ops.shapemove.retarget())
    assert result == ["FINISHED"] and finished and errors == []
    assert sorted(o.type for o in new) == ["ARMATURE", "MESH"]
    rig = next(o for o in new if o.type == "ARMATURE")
    sync = ext("shapemove_addon.shape_sync")
    assert keyed_frames(rig) > 20
    assert np.abs(sync.current_betas(rig) - sync.current_betas(target)).max() < 1e-5  # the target rig's body
    # the action went to the worker as a BVH in the data folder
    data = os.path.dirname(target["shapemove_motion_file"])
    assert len([f for f in os.listdir(data) if f.endswith(".bvh")]) == 1


def test_train_job_publishes_a_selectable_model(torch):
    s = bpy.context.scene.shapemove
    s.train_data, s.train_kind, s.train_steps, s.train_config, s.train_model_name = \
        CONFIG["dataset"], "tma", 2, "tiny", "trained"
    errors, restore = job_messages()
    try:
        assert sorted(bpy.ops.shapemove.train(resume=False)) == ["FINISHED"]
        assert ext("shapemove_addon.job_submit").running("train")
        assert run_jobs(timeout=300)
    finally:
        restore()
    assert errors == []
    assert s.train_result.endswith("trained") and os.path.isfile(os.path.join(s.train_result, "tma", "tma.pt"))
    assert report_error(lambda: bpy.ops.shapemove.use_model()) == ["ok", ["FINISHED"]]
    assert bpy.context.preferences.addons[ADDON].preferences.active_model == s.train_result
