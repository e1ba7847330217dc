"""The preview camera frames the whole motion (shapemove_addon/preview_render.py): every corner of
the motion's bounds at its own depth, so a body running toward the camera keeps its feet in the
picture."""
import math

import numpy as np
import pytest

pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
pytestmark = pytest.mark.blender


def test_framing_distance_fits_the_near_low_corner_by_hand():
    from shapemove.shapemove_addon.preview_render import framing_distance

    e = math.radians(10)
    view = np.array([0.0, math.cos(e), -math.sin(e)])
    lo, hi = np.array([-0.5, -2.0, 0.0]), np.array([0.5, 2.0, 1.8])   # 4 m of travel toward the camera
    tan_w, tan_h = 0.36, 0.27
    d = framing_distance(lo, hi, view, tan_w, tan_h)
    # the corner nearest the camera and lowest, (x, -2, -0.9) about the centre, decides:
    # its height in the picture over its depth is the field's edge shrunk by the margin 1.15
    near_low = 1.15 * (2 * math.sin(e) + 0.9 * math.cos(e)) / tan_h + (2 * math.cos(e) - 0.9 * math.sin(e))
    assert d == pytest.approx(near_low, rel=1e-12)
    # every corner is then inside the shrunk field, that one on its edge
    right, up = np.array([1.0, 0.0, 0.0]), np.array([0.0, math.sin(e), math.cos(e)])
    centre = (lo + hi) / 2
    for x in (lo[0], hi[0]):
        for y in (lo[1], hi[1]):
            for z in (lo[2], hi[2]):
                c = np.array([x, y, z]) - centre
                depth = d + c @ view
                assert abs(c @ right) / depth <= tan_w / 1.15 + 1e-12
                assert abs(c @ up) / depth <= tan_h / 1.15 + 1e-12
    # the framing that ignored the depth of each corner (half the size over the tangent, plus half
    # the travel) stood closer, with the near feet out of the picture
    old = max(1.15 * 1.0 / 2 / tan_w, 1.15 * 1.8 / 2 / tan_h) + 2.0
    assert old < d - 1.0


def test_framing_distance_has_a_floor_for_a_tiny_box():
    from shapemove.shapemove_addon.preview_render import framing_distance

    assert framing_distance([0, 0, 0], [0.01, 0.01, 0.01], [0.0, 1.0, 0.0], 0.36, 0.27) == 0.5


def test_every_preview_panel_frames_the_body(tmp_path):
    """A jog across the room: framed for the whole motion, the body was a sixth to two fifths of the
    panel's height (far down the plane in the first frames); each panel's camera frames the body in
    that frame, so it is at least half the panel's height in every one. The saved scene's camera
    still frames the whole motion."""
    import bpy

    from shapemove.core.generation.generate import Generator, Request
    from shapemove.shapemove_addon.headless import build_scene_file
    from shapemove.shapemove_addon.preview_render import aim_camera, body_share, motion_bounds

    gen = Generator(None)
    m = gen.generate_batch([Request("a person jogs forward", seconds=4, seed=0)])[0]
    info = build_scene_file(m, gen.body, tmp_path / "s.blend", tmp_path / "p.png", frames=3, resolution=(64, 64))
    assert len(info["preview_body_share"]) == 3 and min(info["preview_body_share"]) >= 0.5, info
    scene, rig = bpy.context.scene, bpy.data.objects[info["armature"]]
    whole = [body_share(scene, scene.camera, rig, f) for f in info["preview_frames"]]
    assert min(whole) < 0.5, whole                                # what one framing for the whole jog gave
    aim_camera(scene, scene.camera, *motion_bounds(scene, rig, frames=[info["preview_frames"][0]]))
    assert body_share(scene, scene.camera, rig, info["preview_frames"][0]) >= 0.5
