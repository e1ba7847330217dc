"""Write the retrieval memory of a model folder: the motion tokens of the real captured training
clips (and their mirror images) with their captions, which generation retrieves by caption
similarity (``core/models/motion_memory.py``; retrieved candidates, ``core/generation/generate.py``).

    python tools/build_motion_memory.py --model weights/default --data data/built

Tokens come from the folder's own SA-VAE (``savae.pt``), so they decode as the model's own would:
its base codes, decoded by the base decoder as the T5's are (a residual codec's residual is left
out: generation with clips decoded through the residual branch was judged lower on the held-out
sets, docs/codec.md).
Shape-augmented copies (the same motion on another body) and composed clips (two clips put
together) are left out: the memory holds each captured performance once per side. The folder's
``manifest.json`` is rewritten. Deterministic for a dataset and a codec.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path


def memory_clip_ids(data: Path) -> list[str]:
    """Training clips that are captured motion or its mirror image (sorted ids)."""
    out = []
    for p in sorted((data / "meta").glob("*.json")):
        m = json.loads(p.read_text(encoding="utf-8"))
        if m.get("split") == "train" and not m.get("augmented_from") and not m.get("composed_from"):
            out.append(p.stem)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--model", type=Path, required=True, help="model folder (savae.pt, t5/)")
    p.add_argument("--data", type=Path, required=True, help="the built dataset the model was trained on")
    a = p.parse_args(argv)

    import torch
    from tqdm import tqdm

    from shapemove.core.model_files import write_manifest
    from shapemove.core.models.motion_memory import MotionMemory
    from shapemove.core.models.savae import load_savae
    from shapemove.core.models.text_encoder import load_text_encoder
    from shapemove.core.train.t5_dataset import tokenize_clips

    torch.set_num_threads(1)
    ids = memory_clip_ids(a.data)
    vae = load_savae(a.model / "savae.pt")
    bar = tqdm(total=len(ids), desc="tokens", unit="clip")
    with torch.no_grad():
        tokens = tokenize_clips(vae, a.data, ids, progress=lambda f, c: bar.update(1))
    bar.close()
    mem = MotionMemory.from_dataset(a.data, ids, tokens, load_text_encoder())
    mem.save(a.model / "t5")
    write_manifest(a.model)
    print(f"{a.model / 't5'}: {len(mem)} clips, {len(mem.texts)} captions")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
