"""The ShapeMove panels and operators inside real Blender, as pytest tests in their own process
(started by tests/test_blender_ui.py through ``blender_inside.run``; see ui_support.py).

First with torch unimportable, as in a stock Blender: registering, panel drawing, an OpenBody rig
from the numpy body, semantic sliders, Random/Reset, re-keying a re-decoded motion, exports and
re-imports, error reports. Then torch imports and jobs run through the in-process runner.
Tests run in file order and share the rig through module fixtures.
"""
from __future__ import annotations

import os

import numpy as np
import pytest
from ui_support import (ADDON, CONFIG, MM, addon_panels, allow_torch, bone_heads, counts, draw_panels,
                        draw_preferences, ext, install, keyed_frames, posed_heads, report_error, run_jobs,
                        skeleton_height, torch_imported)

import bpy

FRAMES = CONFIG["frames"]
PANELS = ["SHAPEMOVE_PT_export", "SHAPEMOVE_PT_generate", "SHAPEMOVE_PT_library", "SHAPEMOVE_PT_main",
          "SHAPEMOVE_PT_retarget", "SHAPEMOVE_PT_shape", "SHAPEMOVE_PT_shape_betas", "SHAPEMOVE_PT_train"]


@pytest.fixture(scope="module")
def installed():
    return install()


@pytest.fixture(scope="module")
def rig(installed):
    """A rig built by the operator from a motion file, without torch."""
    before = counts()
    result = bpy.ops.shapemove.build_from_motion(filepath=CONFIG["motion"], rig_name="Rig")
    rig = bpy.context.active_object
    return {"rig": rig, "result": sorted(result), "new_objects": counts()["objects"] - before["objects"]}


# -- without torch -----------------------------------------------------------------------------------
def test_panels_register_and_draw_in_the_factory_scene(installed):
    assert sorted(installed) == ["FINISHED"] and ADDON in bpy.context.preferences.addons
    assert sorted(c.bl_idname for c in addon_panels() if hasattr(bpy.types, c.bl_idname)) == PANELS
    assert not torch_imported()
    assert bpy.context.active_object.name == "Cube"  # factory startup scene
    panels = draw_panels()
    # rig panels hide without a rig; the others draw their inputs and start buttons
    assert panels["SHAPEMOVE_PT_shape"] is None and panels["SHAPEMOVE_PT_export"] is None
    ops = {p: [d["op"] for d in items if d["kind"] == "operator"] for p, items in panels.items() if items}
    assert ops["SHAPEMOVE_PT_generate"] == ["shapemove.read_plan", "shapemove.generate"]   # the plan, then generate
    assert ops["SHAPEMOVE_PT_retarget"] == ["shapemove.retarget"]
    assert ops["SHAPEMOVE_PT_library"] == ["shapemove.library_search"]
    assert ops["SHAPEMOVE_PT_train"] == ["shapemove.train", "shapemove.train"]
    assert [d["props"] for d in panels["SHAPEMOVE_PT_train"] if d["kind"] == "operator"] == [{"resume": False}, {"resume": True}]
    props = [d["prop"] for d in panels["SHAPEMOVE_PT_generate"] if d["kind"] == "prop"]
    assert props == ["prompt", "shape_text", "use_seconds", "seconds", "seed", "temperature", "by_parts", "use_captured"]
    prefs = [d["prop"] for d in draw_preferences() if d["kind"] == "prop"]
    assert prefs == ["body_model", "python_env", "models_dir", "active_model", "device"]


def test_animation_panel_draws_and_lists_the_timeline(installed):
    from ui_support import PanelSelf, RnaLayout

    panel = ext("shapemove_addon.animation_ui").SHAPEMOVE_PT_animation
    assert hasattr(bpy.types, panel.bl_idname)
    assert bpy.ops.shapemove.timeline_add() == {"FINISHED"} and bpy.ops.shapemove.timeline_add() == {"FINISHED"}
    settings = bpy.context.scene.shapemove_animation
    settings.timeline[1].prompt, settings.timeline[1].seconds = "a person waves", 2.5
    log: list = []
    panel.draw(PanelSelf(panel, RnaLayout(log)), bpy.context)
    ops = [d["op"] for d in log if d["kind"] == "operator"]
    assert ops == ["shapemove.animate", "shapemove.timeline_add", "shapemove.timeline_remove", "shapemove.sequence"]
    rows = [d["value"] for d in log if d["kind"] == "prop" and d["data"] == "ShapeMoveTimelineItem"]
    assert rows[2:] == ["a person waves", 2.5] and [d["rows"] for d in log if d["kind"] == "list"] == [2]
    assert bpy.ops.shapemove.timeline_remove() == {"FINISHED"} and len(settings.timeline) == 1


def test_rig_from_a_motion_file_without_torch(rig):
    r = rig["rig"]
    assert rig["result"] == ["FINISHED"] and rig["new_objects"] == 2
    body = ext("core.scene.bodies").load_body("openbody-v1")
    assert type(body).__name__ == "BodyArrays" and not torch_imported()
    assert r.get("shapemove_has_tokens") and r.get("shapemove_motion_file").endswith("motion.npz")
    assert keyed_frames(r) == FRAMES
    # the rig's bones sit on the numpy body's rest joints (Z-up)
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    motion = ext("core.scene.motion_file").load_motion(CONFIG["motion"])
    rest = ext("core.scene.axes").points_to_z_up(body.rest_joints(motion.betas)[0])
    assert np.abs(bone_heads(r, names) - rest).max() < 1e-5
    panels = draw_panels()
    shape = panels["SHAPEMOVE_PT_shape"] or []
    assert [d["prop"] for d in shape if d["kind"] == "prop" and d["data"] == "ShapeMoveObjectProperties"] == \
        ["height", "weight", "age", "muscle", "gender", "proportions"]
    assert [d["index"] for d in panels["SHAPEMOVE_PT_shape_betas"] or [] if d["kind"] == "prop" and d["prop"] == "betas"] \
        == list(range(10))
    export_ops = [x for x in panels["SHAPEMOVE_PT_export"] if x["kind"] == "operator"]
    assert export_ops == [{"kind": "operator", "op": "shapemove.export", "text": "Export", "props": {"format": "FBX"}}]


def test_redecoded_motion_replaces_the_keys(rig):
    r = rig["rig"]
    names = list(ext("core.body.skeleton").JOINT_NAMES)[:22]
    m2 = ext("core.scene.motion_file").load_motion(CONFIG["motion2"])
    actions_before, old_name = len(bpy.data.actions), r.animation_data.action.name
    ext("shapemove_addon.redecode").apply_motion(r, m2)
    for k in (0, m2.num_frames // 2, m2.num_frames - 1):  # the rig now plays motion 2 exactly
        bpy.context.scene.frame_set(1 + k)
        assert np.abs(posed_heads(r, names) - ext("core.scene.axes").points_to_z_up(m2.joints[k])).max() < MM
    assert len(bpy.data.actions) == actions_before and r.animation_data.action.name == old_name
    assert keyed_frames(r) == FRAMES


def test_semantic_height_slider_makes_the_skeleton_taller(rig):
    r = rig["rig"]
    sync, redecode = ext("shapemove_addon.shape_sync"), ext("shapemove_addon.redecode")
    body = ext("shapemove_addon.semantic_shape").semantic_body(r)
    b0, h0 = sync.current_betas(r).copy(), skeleton_height(r)
    p0, w0 = r.shapemove.height, r.shapemove.weight
    r.shapemove.height = p0 + 0.1  # the slider
    b1 = sync.current_betas(r)
    assert r.shapemove.height == pytest.approx(p0 + 0.1, abs=1e-6)
    # exactly 0.1 x the height row of the phenotype map
    assert np.allclose(b1 - b0, 0.1 * body.phenotype_matrix[body.phenotype_names.index("height")], atol=1e-5)
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    rest = ext("core.scene.axes").points_to_z_up(body.rest_joints(b1)[0])
    assert skeleton_height(r) > h0 + 0.02 and np.abs(bone_heads(r, names) - rest).max() < 1e-5
    assert abs(r.shapemove.weight - w0) < 1e-6
    # the motion follows: a debounced re-decode job is pending
    assert sorted(redecode.pending()) == ["Rig"] and bpy.app.timers.is_registered(redecode._fire)


def test_random_and_reset(rig):
    r = rig["rig"]
    sync = ext("shapemove_addon.shape_sync")
    body = ext("shapemove_addon.semantic_shape").semantic_body(r)
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    axes = ext("core.scene.axes")
    bpy.context.view_layer.objects.active = r
    assert sorted(bpy.ops.shapemove.random_shape(seed=3)) == ["FINISHED"]
    b_rand = sync.current_betas(r).copy()
    assert np.allclose(b_rand, np.clip(np.random.default_rng(3).normal(0, 1, 10), -5, 5), atol=1e-6)
    assert np.abs(bone_heads(r, names) - axes.points_to_z_up(body.rest_joints(b_rand)[0])).max() < 1e-5
    assert sorted(bpy.ops.shapemove.reset_shape()) == ["FINISHED"]
    assert sync.current_betas(r).tolist() == [0.0] * 10
    assert np.abs(bone_heads(r, names) - axes.points_to_z_up(body.joint_template)).max() < 1e-5


def test_exports_reimport_with_the_same_bones_and_frames(rig):
    r = rig["rig"]
    export = ext("shapemove_addon.export")
    vertices = len(ext("shapemove_addon.rig_state").body_of(r).data.vertices)
    assert len(r.data.bones) == 24 and keyed_frames(r) == FRAMES
    for fmt, ext_ in export.FORMATS.items():
        path = os.path.join(CONFIG["export_dir"], "rig" + ext_)
        bpy.context.view_layer.objects.active = r
        out = export.export_rig(bpy.context, r, path, fmt)
        before = set(bpy.data.objects)
        if fmt == "FBX":
            bpy.ops.import_scene.fbx(filepath=str(out))
        elif fmt == "GLTF":
            bpy.ops.import_scene.gltf(filepath=str(out))
        else:
            bpy.ops.import_anim.bvh(filepath=str(out))
        new = [o for o in bpy.data.objects if o not in before]
        arm = next(o for o in new if o.type == "ARMATURE")
        assert os.path.getsize(out) > 1000, fmt
        assert not any(f.endswith(".tmp" + ext_) for f in os.listdir(CONFIG["export_dir"])), fmt
        assert len(arm.data.bones) == 24, fmt
        assert arm.animation_data and arm.animation_data.action and keyed_frames(arm) == FRAMES, fmt
        meshes = sorted([len(o.data.vertices), len(o.data.shape_keys.key_blocks) if o.data.shape_keys else 0]
                        for o in new if o.type == "MESH")
        # the body comes back with its 10 shape keys (+ Basis) from FBX and glTF (the glTF importer
        # may add a small bone-shape mesh); BVH is skeleton only
        if fmt == "BVH":
            assert meshes == []
        else:
            assert [m for m in meshes if m[0] == vertices] == [[vertices, 11]], fmt
        for o in new:
            bpy.data.objects.remove(o)
    # through the operator (Export panel)
    bpy.context.view_layer.objects.active = r
    path = os.path.join(CONFIG["export_dir"], "op.bvh")
    assert report_error(lambda: bpy.ops.shapemove.export(filepath=path, format="BVH")) == ["ok", ["FINISHED"]]
    assert os.path.isfile(path)


def test_bad_input_is_reported_and_changes_nothing(rig):
    before = counts()
    r = report_error(lambda: bpy.ops.shapemove.build_from_motion(filepath=CONFIG["missing_motion"]))
    assert r[0] == "error" and "motion file not found" in r[1]
    r = report_error(lambda: bpy.ops.shapemove.build_from_motion(filepath=CONFIG["corrupt_motion"]))
    assert r[0] == "error" and "cannot read motion file" in r[1]
    s = bpy.context.scene.shapemove
    s.prompt = "   "
    r = report_error(lambda: bpy.ops.shapemove.generate())
    assert r[0] == "error" and "prompt is empty" in r[1]
    s.retarget_source, s.retarget_path = "FILE", CONFIG["missing_motion"]
    r = report_error(lambda: bpy.ops.shapemove.retarget())
    assert r[0] == "error" and "motion file not found" in r[1]
    s.train_data = CONFIG["missing_motion"]
    r = report_error(lambda: bpy.ops.shapemove.train())
    assert r[0] == "error" and "dataset folder not found" in r[1]
    assert counts() == before


def test_retarget_file_overrides_reach_the_job_parameters():
    s = bpy.context.scene.shapemove
    overrides = ext("shapemove_addon.operators").reader_overrides
    assert overrides(s) == {}                                   # as the file declares
    s.retarget_source_fps, s.retarget_angle_unit = 30.0, "RAD"
    try:
        assert overrides(s) == {"source_fps": 30.0, "angle_unit": "rad"}
    finally:
        s.retarget_source_fps, s.retarget_angle_unit = 0.0, "FILE"


# -- torch imports from here on: jobs in this process ------------------------------------------------
@pytest.fixture(scope="module")
def in_process(rig):
    allow_torch()
    jobs, client = ext("shapemove_addon.jobs"), ext("core.worker.client")
    jobs.manager().set_runner(client.InProcessRunner())
    return rig["rig"]


def test_measure_job_in_process_updates_the_rig(in_process):
    r, jobs = in_process, ext("shapemove_addon.jobs")
    bpy.context.view_layer.objects.active = r
    assert r.shapemove.height_cm == 0.0 and ext("shapemove_addon.shape_sync").current_betas(r).tolist() == [0.0] * 10
    assert sorted(bpy.ops.shapemove.measure()) == ["FINISHED"]
    assert ext("shapemove_addon.job_submit").running("measure")
    # while the job runs, the Shape panel shows its progress and a Cancel button
    shown = [d for d in draw_panels()["SHAPEMOVE_PT_shape"] if d["kind"] in ("progress", "operator")
             and d.get("op") in (None, "shapemove.cancel_job")]
    assert "progress" in [d["kind"] for d in shown]
    assert {"kind": "operator", "op": "shapemove.cancel_job", "text": "", "props": {"kind": "measure"}} in shown
    assert run_jobs() and type(jobs.manager().runner).__name__ == "InProcessRunner"
    want = CONFIG["zero_measure"]  # measured on the torch body in the main test process
    assert r.shapemove.height_cm == pytest.approx(want["height_cm"], abs=0.05)
    assert r.shapemove.waist_cm == pytest.approx(want["waist_cm"], abs=0.05)


def test_shape_from_text_job_sets_the_betas(in_process):
    r = in_process
    bpy.context.view_layer.objects.active = r
    bpy.context.scene.shapemove.shape_from_text = CONFIG["shape_text"]
    h0 = skeleton_height(r)
    assert sorted(bpy.ops.shapemove.shape_from_text()) == ["FINISHED"] and run_jobs()
    assert np.allclose(ext("shapemove_addon.shape_sync").current_betas(r), CONFIG["text_betas"], atol=1e-5)
    assert r.shapemove.height_cm == pytest.approx(185.0, abs=1.0) and skeleton_height(r) > h0


def test_missing_or_dead_worker_is_an_error_and_changes_nothing(in_process):
    r = in_process
    prefs = bpy.context.preferences.addons[ADDON].preferences
    bpy.context.view_layer.objects.active = r
    before, h = counts(), r.shapemove.height_cm
    prefs.python_env = os.path.join(CONFIG["home"], "no-such-python")
    missing = report_error(lambda: bpy.ops.shapemove.measure())
    assert missing[0] == "error" and "Python environment not found" in missing[1]
    # a worker that starts and dies at once: the job ends with an error, the rig is untouched
    exe = os.path.join(CONFIG["home"], "dies.sh")
    with open(exe, "w") as f:
        f.write("#!/bin/sh\nexit 3\n")
    os.chmod(exe, 0o755)
    prefs.python_env = exe
    errors = []
    jobs = ext("shapemove_addon.jobs")
    assert report_error(lambda: bpy.ops.shapemove.measure()) == ["ok", ["FINISHED"]]
    job_id = next(iter(jobs.manager().jobs), None)
    assert job_id is not None
    job = jobs.manager().jobs[job_id]
    job.on_error = (lambda orig: (lambda msg: (errors.append(msg["message"]), orig(msg))))(job.on_error)
    assert run_jobs(timeout=30)
    prefs.python_env = ""
    assert len(errors) == 1 and "worker process died" in errors[0]
    assert counts() == before and r.shapemove.height_cm == h
