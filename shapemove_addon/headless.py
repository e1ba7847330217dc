"""Headless scene files and previews (bpy as a module, no UI): used by the `demo`, `blend` and
`render` commands. A fresh factory scene per motion; outputs written atomically."""
from __future__ import annotations

import tempfile
from pathlib import Path

import bpy
import numpy as np

from ..core.atomic import atomic_path
from .preview_render import add_preview_stage, aim_camera, body_share, motion_bounds, render_frame
from .animation_rig import build_animated_rig


def save_blend(path: Path) -> Path:
    path = Path(path)
    with atomic_path(path, suffix=".blend") as tmp:
        bpy.ops.wm.save_as_mainfile(filepath=str(tmp.resolve()), compress=True, copy=True)
    return path


def _pixels(png: Path) -> np.ndarray:
    img = bpy.data.images.load(str(png), check_existing=False)
    try:
        w, h = img.size
        px = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
        return px.reshape(h, w, 4)
    finally:
        bpy.data.images.remove(img)


def write_strip(frames: list[np.ndarray], path: Path) -> Path:
    """Frames (h,w,4) side by side into one PNG (atomic)."""
    strip = np.concatenate(frames, axis=1)
    h, w = strip.shape[:2]
    img = bpy.data.images.new("shapemove_strip", w, h, alpha=True)
    try:
        img.pixels.foreach_set(strip.ravel())
        with atomic_path(path, suffix=".png") as tmp:
            img.filepath_raw = str(tmp)
            img.file_format = "PNG"
            img.save()
    finally:
        bpy.data.images.remove(img)
    return path


def build_scene_file(motion, body, out_blend: Path, preview: Path | None = None, frames: int = 4,
                     resolution=(320, 320), name: str = "ShapeMove", root_motion: str = "PELVIS") -> dict:
    """New scene with the rig for ``motion`` (a loop cycles, a timeline gets NLA strips, the root
    travel goes where ``root_motion`` says: ``animation_rig``); saves ``out_blend``; with
    ``preview`` renders ``frames`` evenly spaced frames into one PNG strip, the camera framing the
    body in each (a jog across the room stays large in every panel; ``preview_body_share``: the
    body's height over each panel's); the saved scene's camera frames the whole motion. Returns
    facts about what was built."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    rig = build_animated_rig(bpy.context, motion, body, name=name, root_motion=root_motion)
    scene = bpy.context.scene
    info = {"armature": rig.armature.name, "vertices": len(rig.body.data.vertices),
            "bones": len(rig.armature.data.bones), "frame_start": scene.frame_start, "frame_end": scene.frame_end}
    if preview is not None:
        cam = add_preview_stage(bpy.context, rig.armature, resolution=tuple(resolution))
        whole = motion_bounds(scene, rig.armature)
        picks = np.unique(np.linspace(scene.frame_start, scene.frame_end, frames).round().astype(int))
        shares = []
        with tempfile.TemporaryDirectory() as tmp:
            shots = []
            for f in picks:
                aim_camera(scene, cam, *motion_bounds(scene, rig.armature, frames=[int(f)]))
                shares.append(body_share(scene, cam, rig.armature, int(f)))
                png = Path(tmp) / f"f{int(f):05d}.png"
                render_frame(scene, int(f), png)
                shots.append(_pixels(png))
        write_strip(shots, preview)
        aim_camera(scene, cam, *whole)
        scene.frame_set(scene.frame_start)
        info["preview_frames"] = [int(f) for f in picks]
        info["preview_body_share"] = [round(x, 3) for x in shares]
    save_blend(out_blend)
    return info


def render_video(blend: Path, mp4: Path) -> Path:
    """Every frame of the saved preview scene to an H.264 MP4 (atomic)."""
    bpy.ops.wm.open_mainfile(filepath=str(Path(blend).resolve()))
    scene = bpy.context.scene
    r = scene.render
    if hasattr(r.image_settings, "media_type"):  # Blender 5.0+: FFMPEG is a video media type
        r.image_settings.media_type = "VIDEO"
    r.image_settings.file_format = "FFMPEG"
    r.ffmpeg.format = "MPEG4"
    r.ffmpeg.codec = "H264"
    mp4 = Path(mp4)
    with atomic_path(mp4, suffix=".mp4") as tmp:
        r.filepath = str(tmp.resolve())
        r.use_file_extension = False
        bpy.ops.render.render(animation=True)
    return mp4
