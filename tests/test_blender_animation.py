"""The animation rigs in real bpy (shapemove_addon/animation_rig.py): a loop cycles for ever with
the root advancing per cycle, root motion on the pelvis / object / root bone / none gives the
same world motion (or none), a timeline plays as NLA strips, and the FBX export carries it."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.scene.motion_file import make_motion

bpy = pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
from bpy_readback import bone_heads_world  # noqa: E402
pytestmark = pytest.mark.blender

P = 16
ADV = np.array([0.3, 0.0, 1.2])   # Y up: 1.24 m per cycle


def _loop(body):
    t = np.arange(P)[:, None, None]
    rng = np.random.default_rng(1)
    poses = 0.3 * rng.normal(size=(1, 24, 3)) * np.sin(2 * np.pi * t / P + rng.uniform(0, 6, (1, 24, 3)))
    transl = np.arange(P)[:, None] * ADV[None] / P + [0.0, 0.9, 0.0] + [0.0, 0.02, 0.0] * np.sin(4 * np.pi * t[:, 0] / P)
    return make_motion(body, poses, transl, np.zeros(10), fps=20, prompt="loop test", loop_advance=ADV.astype(np.float32))


def _pelvis(arm, frame):
    bpy.context.scene.frame_set(frame)
    return bone_heads_world(arm, ["pelvis"])[0]


@pytest.mark.parametrize("mode", ["PELVIS", "OBJECT", "ROOT_BONE", "NONE"])
def test_loop_cycles_with_root_advance(openbody, mode):
    from shapemove.shapemove_addon.animation_rig import build_animated_rig

    bpy.ops.wm.read_factory_settings(use_empty=True)
    m = _loop(openbody)
    rig = build_animated_rig(bpy.context, m, openbody, name="Loop", root_motion=mode)
    arm = rig.armature
    adv_z_up = np.array([ADV[0], -ADV[2], ADV[1]])
    for f in (1, 5, 12):   # one, two and three cycles later: the same pose, moved by the advance
        a, b, c = _pelvis(arm, f), _pelvis(arm, f + P), _pelvis(arm, f + 2 * P)
        want = adv_z_up if mode != "NONE" else np.zeros(3)
        np.testing.assert_allclose(b - a, want, atol=1e-4)
        np.testing.assert_allclose(c - b, want, atol=1e-4)
    # the world pose of frame 5 is the motion's, whatever carries the travel
    expect = m.joints[4, 0] if mode != "NONE" else m.joints[4, 0] - [m.joints[4, 0, 0] - m.joints[0, 0, 0], 0,
                                                                   m.joints[4, 0, 2] - m.joints[0, 0, 2]]
    np.testing.assert_allclose(_pelvis(arm, 5), [expect[0], -expect[2], expect[1]], atol=1e-4)
    assert ("root" in arm.data.bones) == (mode == "ROOT_BONE")


def test_a_loop_whose_rotations_turn_over_repeats_them(openbody):
    """A bone that turns a full circle over the cycle (a swung arm, a captured kick's hip) ends its
    continuous quaternion keys at -q where it started at q: the same rotation. Repeated with an
    offset, the next cycle would add -2q to every key of that bone and bend the limb anywhere; the
    rotations repeat, the translation advances."""
    from shapemove.shapemove_addon.animation_rig import build_animated_rig

    bpy.ops.wm.read_factory_settings(use_empty=True)
    t = np.arange(P)
    poses = np.zeros((P, 24, 3))
    poses[:, 16, 2] = 2 * np.pi * t / P                    # the left shoulder: one turn a cycle
    transl = np.arange(P)[:, None] * ADV[None] / P + [0.0, 0.9, 0.0]
    m = make_motion(openbody, poses, transl, np.zeros(10), fps=20, prompt="arm circles",
                    loop_advance=ADV.astype(np.float32))
    rig = build_animated_rig(bpy.context, m, openbody, name="Circles", root_motion="PELVIS")
    arm = rig.armature
    adv_z_up = np.array([ADV[0], -ADV[2], ADV[1]])
    for f in (3, 9, 14):
        bpy.context.scene.frame_set(f)
        a = bone_heads_world(arm, ["left_wrist"])[0]
        bpy.context.scene.frame_set(f + P)
        b = bone_heads_world(arm, ["left_wrist"])[0]
        np.testing.assert_allclose(b - a, adv_z_up, atol=1e-4)


@pytest.mark.parametrize("mode", ["OBJECT", "ROOT_BONE", "NONE"])
def test_a_redecoded_motion_keeps_the_rigs_root_motion(openbody, mode):
    """A shape change re-decodes the motion (``redecode.apply_motion``): the new keys go where the
    rig was built to carry the travel: on the object, on the root bone, or nowhere (in place), not
    back on the pelvis."""
    from shapemove.shapemove_addon.animation_rig import build_animated_rig
    from shapemove.shapemove_addon.redecode import apply_motion

    bpy.ops.wm.read_factory_settings(use_empty=True)
    m = _loop(openbody)
    m.loop_advance = None
    rig = build_animated_rig(bpy.context, m, openbody, name="Walk", root_motion=mode)
    arm = rig.armature
    before = [(_pelvis(arm, f), bone_heads_world(arm, ["pelvis"])[0] - np.array(arm.matrix_world)[:3, 3])
              for f in (1, 6, 12)]
    apply_motion(arm, m)                                  # the same motion again: nothing may move
    after = [(_pelvis(arm, f), bone_heads_world(arm, ["pelvis"])[0] - np.array(arm.matrix_world)[:3, 3])
             for f in (1, 6, 12)]
    for (w0, local0), (w1, local1) in zip(before, after):
        np.testing.assert_allclose(w1, w0, atol=1e-4)        # the world motion
        np.testing.assert_allclose(local1, local0, atol=1e-4)  # and what carries it
    assert ("root" in arm.data.bones) == (mode == "ROOT_BONE")


def test_a_redecoded_loop_still_cycles(openbody):
    """A loop rig given new keys for a new body (``redecode.apply_motion``, the Shape sliders) keeps
    cycling with the new advance: before, the new action had no Cycles modifiers and stopped after
    one cycle."""
    from shapemove.shapemove_addon.animation_rig import LOOP_KEY, build_animated_rig
    from shapemove.shapemove_addon.redecode import apply_motion

    bpy.ops.wm.read_factory_settings(use_empty=True)
    m = _loop(openbody)
    rig = build_animated_rig(bpy.context, m, openbody, name="Loop", root_motion="PELVIS")
    arm = rig.armature
    longer = make_motion(openbody, m.poses, m.transl, np.zeros(10), fps=20, prompt="loop test",
                         loop_advance=(1.1 * ADV).astype(np.float32))
    apply_motion(arm, longer)
    adv_z_up = 1.1 * np.array([ADV[0], -ADV[2], ADV[1]])
    for f in (2, 7):   # one and two cycles later: the same pose moved by the new advance
        a, b, c = _pelvis(arm, f), _pelvis(arm, f + P), _pelvis(arm, f + 2 * P)
        np.testing.assert_allclose(b - a, adv_z_up, atol=1e-4)
        np.testing.assert_allclose(c - b, adv_z_up, atol=1e-4)
    assert arm[LOOP_KEY] == P and tuple(arm.animation_data.action.frame_range) == (1.0, 1.0 + P)


def test_timeline_nla_strips_play_the_segments(openbody):
    from shapemove.shapemove_addon.animation_rig import TRACK_NAME, build_animated_rig

    bpy.ops.wm.read_factory_settings(use_empty=True)
    m = _loop(openbody)
    m.loop_advance = None
    m.segment_bounds, m.segment_prompts = np.array([[0, 6], [6, 16]]), ["walks", "waves"]
    rig = build_animated_rig(bpy.context, m, openbody, name="Timeline")
    strips = rig.armature.animation_data.nla_tracks[TRACK_NAME].strips
    assert [(s.name, s.frame_start, s.frame_end) for s in strips] == [("walks", 1.0, 7.0), ("waves", 7.0, 17.0)]
    assert rig.armature.animation_data.action is None
    for f in (3, 9, 15):
        j = m.joints[f - 1, 0]
        np.testing.assert_allclose(_pelvis(rig.armature, f), [j[0], -j[2], j[1]], atol=1e-4)
    strips[1].frame_start_ui = 30.0   # re-timed: the second segment now starts at frame 30
    j = m.joints[8, 0]
    np.testing.assert_allclose(_pelvis(rig.armature, 32), [j[0], -j[2], j[1]], atol=1e-4)
    # a shape change decodes the timeline again (redecode.apply_motion): the strips play the new
    # keys with the timing the user gave them, no active action plays over them, the old one is gone
    from shapemove.shapemove_addon.redecode import apply_motion

    old = strips[0].action
    old_name = old.name
    m.transl[:, 0] += 0.5                                   # the "new" motion: moved half a metre
    apply_motion(rig.armature, m)
    strips = rig.armature.animation_data.nla_tracks[TRACK_NAME].strips
    assert rig.armature.animation_data.action is None and strips[0].action == strips[1].action
    assert strips[0].action.name == old_name and len(bpy.data.actions) == 1      # replaced, same name
    assert [s.frame_start for s in strips] == [1.0, 30.0]
    for f, k in ((3, 2), (32, 8)):
        j = m.joints[k, 0] + [0.5, 0.0, 0.0]
        np.testing.assert_allclose(_pelvis(rig.armature, f), [j[0], -j[2], j[1]], atol=1e-4)


@pytest.mark.parametrize("mode", ["OBJECT", "ROOT_BONE"])
def test_fbx_carries_root_motion(openbody, tmp_path, mode):
    from shapemove.shapemove_addon import export
    from shapemove.shapemove_addon.animation_rig import build_animated_rig

    bpy.ops.wm.read_factory_settings(use_empty=True)
    m = _loop(openbody)
    rig = build_animated_rig(bpy.context, m, openbody, name="Rig", root_motion=mode)
    ref = {f: _pelvis(rig.armature, f) for f in (1, 8, P + 1)}
    path = export.export_rig(bpy.context, rig.armature, tmp_path / "rig.fbx", "FBX")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.fbx(filepath=str(path))
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    assert ("root" in arm.data.bones) == (mode == "ROOT_BONE")
    for f, want in ref.items():   # Blender's FBX importer puts the file's frame 0 at frame 1
        np.testing.assert_allclose(_pelvis(arm, f), want, atol=2e-3)


def test_fbx_of_a_timeline(openbody, tmp_path):
    from shapemove.shapemove_addon import export
    from shapemove.shapemove_addon.animation_rig import TRACK_NAME, build_animated_rig

    bpy.ops.wm.read_factory_settings(use_empty=True)
    m = _loop(openbody)
    m.loop_advance = None
    m.segment_bounds, m.segment_prompts = np.array([[0, 6], [6, 16]]), ["walks", "waves"]
    rig = build_animated_rig(bpy.context, m, openbody, name="Timeline")
    ref = {f: _pelvis(rig.armature, f) for f in (1, 4, 9, 16)}
    path = export.export_rig(bpy.context, rig.armature, tmp_path / "timeline.fbx", "FBX")
    strips = rig.armature.animation_data.nla_tracks[TRACK_NAME].strips
    assert [s.frame_start for s in strips] == [1.0, 7.0]      # put back after the export
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.fbx(filepath=str(path))
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    for f, want in ref.items():
        np.testing.assert_allclose(_pelvis(arm, f), want, atol=2e-3)


def test_curve_object_to_path():
    from shapemove.shapemove_addon.animation_ui import curve_path

    bpy.ops.wm.read_factory_settings(use_empty=True)
    cu = bpy.data.curves.new("path", "CURVE")
    cu.dimensions = "3D"
    sp = cu.splines.new("POLY")
    pts = [(0, 0, 0), (0.5, 1.0, 0), (0, 2.0, 0), (-0.5, 3.0, 0)]   # Blender: forward is +Y, Z up
    sp.points.add(len(pts) - 1)
    for p, co in zip(sp.points, pts):
        p.co = (*co, 1.0)
    obj = bpy.data.objects.new("path", cu)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = (1.0, 0.0, 0.0)
    path = np.array(curve_path(obj, bpy.context))
    # Y up, [x, z]: Blender (X, Y) -> (x, z) = (X, -Y); first point first, world transform applied
    np.testing.assert_allclose(path[0], [1.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(path[-1], [0.5, -3.0], atol=1e-6)
    assert len(path) == 4


def test_regenerated_timeline_keeps_the_other_strips_timing(openbody):
    """What Regenerate Strip does with the new rig: the other strips get the timing the user gave them."""
    from shapemove.shapemove_addon.animation_rig import build_animated_rig
    from shapemove.shapemove_addon.animation_ui import retime_strips, strip_timing

    bpy.ops.wm.read_factory_settings(use_empty=True)
    m = _loop(openbody)
    m.loop_advance = None
    m.segment_bounds, m.segment_prompts = np.array([[0, 5], [5, 10], [10, 16]]), ["a", "b", "c"]
    old = build_animated_rig(bpy.context, m, openbody, name="Old")
    strips = old.armature.animation_data.nla_tracks[0].strips
    strips[2].frame_start_ui = 40.0          # moved by the user
    strips[0].scale = 2.0                    # and slowed down
    timing = {i: t for i, t in enumerate(strip_timing(old.armature)) if i != 1}
    new = build_animated_rig(bpy.context, m, openbody, name="New")
    retime_strips(new.armature, timing)
    got = strip_timing(new.armature)
    assert got[0] == timing[0] and got[2] == timing[2]
    assert got[0][2] == 2.0 and got[2][0] >= 40.0                       # not the fresh 1.0 / 11.0
    assert got[1][2] == 1.0 and got[1][0] == got[0][1]                   # the new strip follows the slowed first


def test_regenerate_strip_asks_for_the_rigs_body_now(openbody, tmp_path, monkeypatch):
    """Regenerate Strip after the Shape sliders moved: the job is asked for the rig's body as the
    sliders left it (the worker makes the timeline again for it), not the body in the motion file."""
    import shapemove
    from shapemove.core.scene.motion_file import save_motion
    from shapemove.shapemove_addon import job_submit
    from shapemove.shapemove_addon.animation_rig import build_animated_rig
    from shapemove.shapemove_addon.redecode import MOTION_FILE_KEY
    from shapemove.shapemove_addon.rig_state import body_of

    bpy.ops.wm.read_factory_settings(use_empty=True)
    shapemove.register()
    try:
        m = _loop(openbody)
        m.loop_advance = None
        m.segment_bounds, m.segment_prompts = np.array([[0, 8], [8, 16]]), ["walks", "waves"]
        rig = build_animated_rig(bpy.context, m, openbody, name="Timeline")
        rig.armature[MOTION_FILE_KEY] = str(save_motion(tmp_path / "t.npz", m))
        body_of(rig.armature).data.shape_keys.key_blocks["beta_0"].value = 1.25   # a slider moved
        bpy.context.view_layer.objects.active = rig.armature
        bpy.context.scene.shapemove_animation.strip_index = 2
        jobs = []
        monkeypatch.setattr(job_submit, "submit_job", lambda op, params, **kw: jobs.append((op, params)) or "j1")
        assert "FINISHED" in bpy.ops.shapemove.regenerate_strip()
        (op, params), = jobs
        assert op == "sequence" and params["regenerate"] == 1 and params["motion"].endswith("t.npz")
        assert params["betas"][0] == pytest.approx(1.25) and params["betas"][1:] == [0.0] * 9
        assert params["captured"] is True              # captured takes compete in the new strip
        bpy.context.scene.shapemove.use_captured = False   # the panel's Captured takes off: a strip of codes
        assert "FINISHED" in bpy.ops.shapemove.regenerate_strip()
        assert jobs[-1][1]["captured"] is False
    finally:
        shapemove.unregister()
        bpy.ops.wm.read_factory_settings(use_empty=True)

