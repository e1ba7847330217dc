"""`python -m shapemove retarget-rig --motion M.npz --blend IN.blend --armature NAME --out OUT.blend
[--preset rigify|mixamo|cc_iclone|FILE.json] [--no-plant-feet]`: bake a ShapeMove motion onto
your own armature in a .blend (the headless twin of the panel's "Your Rig" section).

Which bone plays which body joint: the preset when given, else the bone map stored on the
armature (saved from the panel), else automatic (a shipped preset when the names fit, else the
skeleton's shape). Needs the ``bpy`` module in this Python.
"""
from __future__ import annotations

from pathlib import Path

from ..core.errors import ShapeMoveError
from ..core.scene.bone_map import find_preset
from ..core.scene.motion_file import load_motion


def add_arguments(p):
    p.add_argument("--motion", type=Path, required=True, help="ShapeMove motion file (.npz)")
    p.add_argument("--blend", type=Path, required=True, help=".blend holding your rig")
    p.add_argument("--armature", required=True, help="name of the armature object in the .blend")
    p.add_argument("--out", type=Path, required=True, help="where to save the .blend with the baked action")
    p.add_argument("--preset", default=None, help="bone-map preset: rigify, mixamo, cc_iclone or a .json file")
    p.add_argument("--no-plant-feet", action="store_true", help="do not hold the feet still during contacts")


def run(args) -> int:
    if args.out.suffix.lower() != ".blend":
        raise ShapeMoveError(f"--out must end in .blend, got {args.out}")
    load_motion(args.motion)  # fail on bad input before paying for bpy
    if args.preset is not None:
        find_preset(args.preset)
    try:
        import bpy  # noqa: F401
    except ImportError:
        raise ShapeMoveError("the `retarget-rig` command needs the bpy module: pip install bpy==5.0.1") from None
    from ..shapemove_addon.rig_retarget import retarget_rig_file

    info = retarget_rig_file(args.motion, args.blend, args.armature, args.out, preset=args.preset,
                             plant_feet=not args.no_plant_feet)
    print(f"baked {info['frames']} frames onto {info['armature']} as action {info['action']}: "
          f"{len(info['bones'])} bones, {info['mapping']}, scale {info['scale']:.3f}, "
          f"turned {info['heading_deg']:.0f} deg")
    print(f"wrote {args.out}")
    return 0
