"""`python -m shapemove blend --motion M.npz --out S.blend [--render P.png --frame N]`.

Builds the ShapeMove rig (body mesh with shape keys, armature, keyed action) for a motion file in
a fresh scene and saves it; with --render also adds a camera and ground plane and renders one
frame headless with Workbench. Needs the ``bpy`` module (pip install bpy) in this Python.
"""
from __future__ import annotations

from pathlib import Path

from ..core.atomic import atomic_path
from ..core.errors import ShapeMoveError
from ..core.scene.bodies import load_body
from ..core.scene.motion_file import load_motion


def add_arguments(p):
    p.add_argument("--motion", type=Path, required=True, help="motion file (.npz) from `generate`")
    p.add_argument("--out", type=Path, required=True, help="where to save the .blend")
    p.add_argument("--render", type=Path, help="also render a frame to this PNG")
    p.add_argument("--frame", type=int, default=None, help="frame to render (default: the middle one)")
    p.add_argument("--resolution", type=int, nargs=2, default=(480, 360), metavar=("W", "H"))
    p.add_argument("--body-model-file", type=Path, help="SMPL-family model file, for motions made for one")
    p.add_argument("--name", default="ShapeMove", help="name of the rig objects")


def run(args) -> int:
    if args.out.suffix.lower() != ".blend":
        raise ShapeMoveError(f"--out must end in .blend, got {args.out}")
    motion = load_motion(args.motion)  # fail on bad input before paying for bpy
    body = load_body(motion.body_model, args.body_model_file)
    try:
        import bpy
    except ImportError:
        raise ShapeMoveError("the `blend` command needs the bpy module: pip install bpy==5.0.1") from None
    from ..shapemove_addon.preview_render import add_preview_stage, render_frame
    from ..shapemove_addon.scene_build import build_rig

    bpy.ops.wm.read_factory_settings(use_empty=True)
    rig = build_rig(bpy.context, motion, body, name=args.name)
    scene = bpy.context.scene
    print(f"built {rig.armature.name}: {len(rig.body.data.vertices)} vertices, "
          f"{len(rig.armature.data.bones)} bones, frames {scene.frame_start}-{scene.frame_end} at {motion.fps:g} fps")
    if args.render:
        add_preview_stage(bpy.context, rig.armature, resolution=tuple(args.resolution))
        frame = args.frame if args.frame is not None else (scene.frame_start + scene.frame_end) // 2
        if not scene.frame_start <= frame <= scene.frame_end:
            raise ShapeMoveError(f"--frame {frame} is outside the motion's frames {scene.frame_start}-{scene.frame_end}")
        args.render.parent.mkdir(parents=True, exist_ok=True)
        render_frame(scene, frame, args.render.resolve())
        print(f"rendered frame {frame} to {args.render}")
    with atomic_path(args.out, suffix=".blend") as tmp:
        bpy.ops.wm.save_as_mainfile(filepath=str(tmp.resolve()), compress=True)
    print(f"wrote {args.out}")
    return 0
