"""Assemble the embedded default model folder from training runs, with weights in float16.

    python tools/export_default.py --vae runs/default/vae --t5 runs/default/t5 --tma runs/default/tma \
        --out weights/default

Writes (atomically, into OUT.tmp then renamed): savae.pt, t5/ (save_pretrained + tokenizer +
beta head), tma/tma.pt + tma/tokenizer/, and MODEL_CARD.json (data, licences, metrics, command).
float16 halves the size; the loaders cast back to float32 on load.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT.parent))
from shapemove.core.model_files import write_manifest  # noqa: E402


def half_state(obj):
    if isinstance(obj, torch.Tensor):
        return obj.half() if obj.is_floating_point() else obj
    if isinstance(obj, dict):
        return {k: half_state(v) for k, v in obj.items()}
    return obj


def export_checkpoint(src: Path, dst: Path, keep=("model", "metadata")) -> None:
    ckpt = torch.load(src, map_location="cpu", weights_only=True)
    out = {k: ckpt[k] for k in keep if k in ckpt}
    out["model"] = {k: (v.half() if v.is_floating_point() and not k.endswith(("mean", "std")) else v)
                    for k, v in out["model"].items()}
    dst.parent.mkdir(parents=True, exist_ok=True)
    torch.save(out, dst)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vae", type=Path, required=True)
    ap.add_argument("--t5", type=Path, required=True)
    ap.add_argument("--tma", type=Path, default=None)
    ap.add_argument("--out", type=Path, default=ROOT / "weights" / "default")
    ap.add_argument("--card", type=Path, default=None, help="JSON with data/metrics facts for the model card")
    args = ap.parse_args()
    tmp = args.out.with_name(args.out.name + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    export_checkpoint(args.vae / "savae.pt", tmp / "savae.pt")
    t5_src = args.t5 / "t5"
    shutil.copytree(t5_src, tmp / "t5")
    from safetensors.torch import load_file, save_file

    for f in ("model.safetensors", "beta_head.safetensors"):
        sd = load_file(str(tmp / "t5" / f))
        save_file({k: (v.half() if v.is_floating_point() else v).contiguous() for k, v in sd.items()}, str(tmp / "t5" / f),
                  metadata={"format": "pt"})
    if args.tma is not None:
        export_checkpoint(args.tma / "tma.pt", tmp / "tma" / "tma.pt")
        if (args.tma / "tokenizer").is_dir():  # sentencepiece TMAs only; MiniLM TMAs have none
            shutil.copytree(args.tma / "tokenizer", tmp / "tma" / "tokenizer")
    card = json.loads(args.card.read_text()) if args.card else {}
    (tmp / "MODEL_CARD.json").write_text(json.dumps(card, indent=2))
    licence = ROOT / "weights" / "default" / "LICENSE.txt"  # the weights' CC BY-NC licence + attributions
    if licence.is_file():
        shutil.copy2(licence, tmp / "LICENSE.txt")
    write_manifest(tmp)  # one manifest for the exported (float16) files; the runs' own are dropped
    old = args.out.with_name(args.out.name + ".old")
    shutil.rmtree(old, ignore_errors=True)
    if args.out.exists():
        args.out.rename(old)
    tmp.rename(args.out)
    shutil.rmtree(old, ignore_errors=True)
    size = sum(p.stat().st_size for p in args.out.rglob("*") if p.is_file())
    print(f"wrote {args.out} ({size / 1e6:.1f} MB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
