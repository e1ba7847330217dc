"""Bodies side by side in one picture, at one scale (bpy as a module, headless): `python -m
shapemove body render`. Each body is a plain mesh (vertices already posed, metres, Y up as the core
gives them), placed left to right on a ground plane; an orthographic camera in front, Workbench
shading, so heights and widths compare directly across the row."""
from __future__ import annotations

from pathlib import Path

import bpy
import numpy as np

from ..core.atomic import atomic_path
from .preview_render import BODY_COLOR, GROUND_COLOR

GAP_M = 0.25   # between two bodies' widest points


def render_bodies(meshes: list[tuple[np.ndarray, np.ndarray]], out_png: Path, height_px: int = 640) -> Path:
    """meshes: [(vertices (V,3) metres Y up, faces (F,3))], drawn left to right -> ``out_png``."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    x, lo, hi = 0.0, np.full(3, np.inf), np.full(3, -np.inf)
    for i, (v, f) in enumerate(meshes):
        v = np.asarray(v, np.float64)
        z_up = np.stack([v[:, 0], -v[:, 2], v[:, 1] - v[:, 1].min()], 1)   # Y up -> Z up, facing -Y, feet at 0
        z_up[:, 0] += x - z_up[:, 0].min()
        x = z_up[:, 0].max() + GAP_M
        mesh = bpy.data.meshes.new(f"body_{i}")
        mesh.from_pydata(z_up.tolist(), [], np.asarray(f).tolist())
        mesh.update()
        for p in mesh.polygons:
            p.use_smooth = True
        obj = bpy.data.objects.new(f"body_{i}", mesh)
        obj.color = BODY_COLOR
        scene.collection.objects.link(obj)
        lo, hi = np.minimum(lo, z_up.min(0)), np.maximum(hi, z_up.max(0))
    centre, size = (lo + hi) / 2, hi - lo
    ground = bpy.data.meshes.new("ground")
    w = size[0] / 2 + 1.0
    ground.from_pydata([(-w, -2, 0), (w, -2, 0), (w, 2, 0), (-w, 2, 0)], [], [(0, 1, 2, 3)])
    g = bpy.data.objects.new("ground", ground)
    g.location = (centre[0], centre[1], 0.0)
    g.color = GROUND_COLOR
    scene.collection.objects.link(g)
    cam_data = bpy.data.cameras.new("camera")
    cam_data.type = "ORTHO"
    aspect = (size[0] + 0.4) / (size[2] + 0.3)
    cam_data.ortho_scale = max(size[0] + 0.4, size[2] + 0.3)
    cam = bpy.data.objects.new("camera", cam_data)
    cam.location = (centre[0], lo[1] - 6.0, centre[2])
    cam.rotation_euler = (np.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "OBJECT"
    scene.render.resolution_y = int(height_px)
    scene.render.resolution_x = int(round(height_px * aspect))
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    out_png = Path(out_png)
    with atomic_path(out_png, suffix=".png") as tmp:
        scene.render.filepath = str(Path(tmp).resolve())
        bpy.ops.render.render(write_still=True)
    return out_png
