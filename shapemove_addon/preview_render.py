"""A small stage for previews: camera framing the whole motion (or, aimed again, one frame of it:
``aim_camera``), ground plane, Workbench render.

Used by ``python -m shapemove blend --render`` and the render command; adds its own objects
(camera "<rig>_camera", plane "<rig>_ground") and sets the scene camera and render settings.
"""
from __future__ import annotations

import math

import bpy
import numpy as np
from mathutils import Vector

from .rig_state import body_of

BODY_COLOR = (0.85, 0.35, 0.25, 1.0)
GROUND_COLOR = (0.55, 0.55, 0.55, 1.0)


def motion_bounds(scene, rig, samples: int = 12, frames=None) -> tuple[np.ndarray, np.ndarray]:
    """(min, max) corners (3,) of the evaluated body mesh over ``samples`` frames of the scene range
    (or over the given ``frames``)."""
    body = body_of(rig)
    keep = scene.frame_current
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    if frames is None:
        frames = np.unique(np.linspace(scene.frame_start, scene.frame_end, samples).round().astype(int))
    for f in frames:
        scene.frame_set(int(f))
        ev = body.evaluated_get(bpy.context.evaluated_depsgraph_get())
        co = np.empty(len(ev.data.vertices) * 3, dtype=np.float32)
        ev.data.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3) @ np.array(body.matrix_world)[:3, :3].T + np.array(body.matrix_world)[:3, 3]
        lo, hi = np.minimum(lo, co.min(0)), np.maximum(hi, co.max(0))
    scene.frame_set(keep)
    return lo, hi


def framing_distance(lo, hi, view, tan_w: float, tan_h: float, margin: float = 1.15, least: float = 0.5) -> float:
    """How far from the centre of the box ``lo``-``hi`` (3,) a camera looking at that centre along
    the unit ``view`` (up: the world's +Z) must stand so that all 8 corners of the box are inside
    its field of view (tangents of the half angles ``tan_w``, ``tan_h``) shrunk by ``margin``. A
    motion toward the camera makes its near corners large in the picture: each corner is fitted at
    its own depth, not the centre's."""
    lo, hi, view = (np.asarray(v, np.float64) for v in (lo, hi, view))
    right = np.cross(view, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, view)
    centre = (lo + hi) / 2
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]) - centre
    need = np.maximum(np.abs(corners @ right) * margin / tan_w, np.abs(corners @ up) * margin / tan_h) - corners @ view
    return float(max(need.max(), least))


def add_preview_stage(context, rig, resolution=(320, 240), lens: float = 50.0):
    """Camera in front of the body (it faces -Y) framing the motion's bounds, a ground plane under
    the lowest vertex, Workbench with the body and ground in flat distinct colours. Returns the camera."""
    scene = context.scene
    lo, hi = motion_bounds(scene, rig)
    centre = (lo + hi) / 2
    size = hi - lo
    ground_mesh = bpy.data.meshes.new(f"{rig.name}_ground")
    half = max(size[0], size[1]) / 2 + 1.5
    ground_mesh.from_pydata([(-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0)], [], [(0, 1, 2, 3)])
    ground = bpy.data.objects.new(f"{rig.name}_ground", ground_mesh)
    ground.location = (centre[0], centre[1], lo[2])
    ground.color = GROUND_COLOR
    scene.collection.objects.link(ground)
    body_of(rig).color = BODY_COLOR

    cam_data = bpy.data.cameras.new(f"{rig.name}_camera")
    cam_data.lens = lens
    cam = bpy.data.objects.new(f"{rig.name}_camera", cam_data)
    scene.collection.objects.link(cam)
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    aim_camera(scene, cam, lo, hi)
    scene.camera = cam

    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.color_type = "OBJECT"
    return cam


def aim_camera(scene, cam, lo, hi) -> None:
    """Put ``cam`` in front of the box ``lo``-``hi`` (3,) (the body faces -Y: looking along +Y, 10
    degrees down) at the distance that frames it (``framing_distance``) for the scene's resolution."""
    r = scene.render
    # sensor fit AUTO: the sensor width spans the longer image side
    aspect = r.resolution_x / r.resolution_y
    half_long = cam.data.sensor_width / (2 * cam.data.lens)  # tan(half field of view) along the longer side
    tan_w, tan_h = (half_long, half_long / aspect) if aspect >= 1 else (half_long * aspect, half_long)
    elevation = math.radians(10)
    view = np.array([0.0, math.cos(elevation), -math.sin(elevation)])   # looking along +Y, a little down
    centre = (np.asarray(lo, np.float64) + np.asarray(hi, np.float64)) / 2
    dist = framing_distance(lo, hi, view, tan_w, tan_h)
    cam.location = Vector((centre - dist * view).tolist())
    cam.rotation_euler = (Vector(centre.tolist()) - cam.location).to_track_quat("-Z", "Y").to_euler()


def body_share(scene, cam, rig, frame: int) -> float:
    """The body's height in the picture of ``frame`` as a share of the picture's height: the
    evaluated mesh's vertices seen through ``cam`` (top to bottom, clipped to the picture)."""
    from bpy_extras.object_utils import world_to_camera_view

    body = body_of(rig)
    scene.frame_set(int(frame))
    ev = body.evaluated_get(bpy.context.evaluated_depsgraph_get())
    co = np.empty(len(ev.data.vertices) * 3, dtype=np.float32)
    ev.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3) @ np.array(body.matrix_world)[:3, :3].T + np.array(body.matrix_world)[:3, 3]
    step = max(1, len(co) // 2000)   # a sample of the vertices is plenty for the extent
    ys = np.array([world_to_camera_view(scene, cam, Vector(v.tolist())).y for v in co[::step]])
    return float(np.clip(ys, 0.0, 1.0).max() - np.clip(ys, 0.0, 1.0).min())


def render_frame(scene, frame: int, path) -> str:
    """Render ``frame`` of ``scene`` to the PNG ``path`` (headless is fine)."""
    scene.frame_set(int(frame))
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return str(path)
