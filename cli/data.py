"""`python -m shapemove data build --source PATH [PATH ...] --out DIR` and
`python -m shapemove data compose --data DIR --count N --seed 0`,
`python -m shapemove data library --data DIR --out LIBRARY.npz` (data/library_build.py)."""
from __future__ import annotations

from pathlib import Path

from ..core.data.build import AUGMENT_SHARE, build_dataset
from ..core.data.compose import compose_dataset
from ..core.errors import ShapeMoveError


def add_arguments(p):
    sub = p.add_subparsers(dest="action", required=True)
    b = sub.add_parser("build", help="mocap folders/archives -> HumanML3D-style dataset (resumable)")
    b.add_argument("--source", type=Path, nargs="+", required=True,
                   help="folder or .tar.xz/.zip: the ../shared/data layout (bandai/, hdm05/, cmu/) or any "
                        "folder of BVH/AMC files with optional same-name .txt captions")
    b.add_argument("--out", type=Path, required=True)
    b.add_argument("--body-model", default=None, help="openbody (default) or a path to SMPL model files")
    b.add_argument("--augment-share", type=float, default=None,
                   help="fraction of Bandai clips that get a copy on a sampled body (default 0.5)")
    b.add_argument("--limit", type=int, default=None, help="only the first N clips (for a quick look)")
    b.add_argument("--ik-refine-iters", type=int, default=10,
                   help="LBFGS refinement steps after the analytic IK (0 = analytic only, faster)")
    b.add_argument("--shard", default="0/1", help="i/n: build every n-th clip starting at i (run n processes on one --out)")
    b.add_argument("--only", nargs="*", default=None, help="only clips whose id starts with one of these")
    c = sub.add_parser("compose", help="add 'A, then B' clips joined with a blended transition to a built dataset")
    c.add_argument("--data", type=Path, required=True, help="a dataset folder made by `data build`")
    c.add_argument("--count", type=int, default=1000, help="number of composed clips to add")
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--body-model", default=None, help="openbody (default) or a path to SMPL model files")
    cp = sub.add_parser("compose-parts", help="add 'legs of a walk/run + arms of a gesture' clips (two things at once)")
    cp.add_argument("--data", type=Path, required=True, help="a dataset folder made by `data build`")
    cp.add_argument("--count", type=int, default=800, help="number of composed clips to add")
    cp.add_argument("--seed", type=int, default=0)
    cp.add_argument("--body-model", default=None, help="openbody (default) or a path to SMPL model files")
    m = sub.add_parser("mirror", help="add the mirror image (left <-> right, captions too) of every training clip")
    m.add_argument("--data", type=Path, required=True, help="a dataset folder made by `data build`")
    m.add_argument("--body-model", default=None, help="openbody (default) or a path to SMPL model files")
    m.add_argument("--shard", default="0/1", help="i/n: mirror every n-th clip starting at i (n processes on one --data)")
    lb = sub.add_parser("library", help="the captured takes of a built dataset (train + val) as one motion library .npz")
    lb.add_argument("--data", type=Path, required=True, help="a dataset folder made by `data build`")
    lb.add_argument("--out", type=Path, required=True, help="the library file to write (.npz)")
    lb.add_argument("--model", type=Path, default=None,
                    help="the model folder whose TMA embeds the captions (default: the embedded default model)")
    lb.add_argument("--body-model", default=None, help="openbody (default) or a path to SMPL model files")


def _shard(text: str) -> tuple[int, int]:
    try:
        shard = tuple(int(v) for v in text.split("/"))
        assert len(shard) == 2
    except (ValueError, AssertionError):
        raise ShapeMoveError(f"--shard must look like 0/2, got {text!r}") from None
    return shard


def _library(args) -> int:
    from tqdm import tqdm

    from ..core.body.load import load_body_model
    from ..core.data.library_build import build_library
    from ..core.generation.model_bundle import model_files, resolve_model_dir
    from ..core.model_files import add_to_manifest

    if args.out.suffix.lower() != ".npz":
        raise ShapeMoveError(f"--out must end in .npz, got {args.out}")
    model = resolve_model_dir(args.model)
    tma = model_files(model)["tma"]
    bar = tqdm(total=100, desc="library", unit="%")
    lib = build_library(args.data, args.out, body=load_body_model(args.body_model),
                        tma_file=tma if tma.is_file() else None,
                        progress=lambda f, cid: bar.update(round(100 * f) - bar.n))
    bar.close()
    out = args.out.resolve()
    if out.parent == model.resolve() and (model / "manifest.json").is_file():
        add_to_manifest(model, [out])   # the model folder's manifest lists it, as its other files
    frames = int(lib.frames.sum())
    print(f"wrote {args.out}: {len(lib)} takes, {frames / 20 / 60:.1f} min, {args.out.stat().st_size / 1e6:.1f} MB"
          + ("" if tma.is_file() else " (no TMA: no caption vectors)"))
    return 0


def run(args) -> int:
    if args.action == "library":
        return _library(args)
    if args.action == "compose-parts":
        from ..core.body.load import load_body_model
        from ..core.data.compose_parts import compose_parts_dataset

        ids = compose_parts_dataset(args.data, args.count, seed=args.seed, body=load_body_model(args.body_model))
        print(f"legs-and-arms clips written: {len(ids)} (training split); split lists and Mean/Std refreshed")
        return 0
    if args.action == "mirror":
        from ..core.body.load import load_body_model
        from ..core.data.mirror import mirror_dataset

        ids = mirror_dataset(args.data, body=load_body_model(args.body_model), shard=_shard(args.shard))
        print(f"mirrored clips written: {len(ids)} (training split); split lists and Mean/Std refreshed")
        return 0
    if args.action == "compose":
        from ..core.body.load import load_body_model

        ids = compose_dataset(args.data, args.count, seed=args.seed, body=load_body_model(args.body_model))
        print(f"composed clips written: {len(ids)} (training split); {args.data}/meta.jsonl, split lists and Mean/Std refreshed")
        return 0
    from ..core.body.load import load_body_model

    shard = _shard(args.shard)
    body = load_body_model(args.body_model)
    report = build_dataset(args.source, args.out, body=body,
                           augment_share=AUGMENT_SHARE if args.augment_share is None else args.augment_share,
                           limit=args.limit, only=args.only, ik_refine_iters=args.ik_refine_iters, shard=shard)
    print(report.summary())
    return 0 if report.built + report.skipped_done + report.augmented > 0 else 1
