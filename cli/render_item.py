"""The item task of ``render``: the item's motion (as ``generate --prompts`` makes it) to
``{stem}.npz``, ``{stem}.blend`` and the ``{stem}.png`` strip of frames, with ``--video``
``{stem}.mp4``. Needs bpy in the process that runs it (each worker of ``--jobs`` / ``--dask``)."""
from __future__ import annotations

from pathlib import Path

from ..core.batch.generate_item import LOCK, item_motion, motion_facts
from ..core.scene.motion_file import save_motion


def render_item(spec: dict, folder: Path) -> dict:
    from ..shapemove_addon.headless import build_scene_file, render_video

    s, stem = spec["settings"], Path(folder) / spec["stem"]
    with LOCK:   # bpy has one scene per process
        motion, gen = item_motion(spec)
        save_motion(stem.with_suffix(".npz"), motion)
        build_scene_file(motion, gen.body, stem.with_suffix(".blend"), stem.with_suffix(".png"),
                         frames=s["frames"], resolution=tuple(s["resolution"]),
                         root_motion=spec["options"]["root_motion"])
        files = [stem.with_suffix(x).name for x in (".npz", ".blend", ".png")]
        if s["video"]:
            render_video(stem.with_suffix(".blend"), stem.with_suffix(".mp4"))
            files.append(stem.with_suffix(".mp4").name)
    return {"files": files, **motion_facts(motion)}
