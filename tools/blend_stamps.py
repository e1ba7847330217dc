"""What Blender stamps into a saved ``.blend`` that is not a function of the scene (docs/batches.md):
the same motion built into a scene and saved twice in one process, as ``render`` does for an item,
then compared.

    python tools/blend_stamps.py --prompt "a person walks forward" --seconds 4

Prints whether the two preview strips (``.png``) are identical, the sizes of the two compressed
``.blend`` files, and for uncompressed saves the bytes that differ and the kinds of file block
(``GLOB``: the file's globals, ``OB`` objects, ``DATA`` ...) they lie in.
"""
from __future__ import annotations

import argparse
import struct
import sys
import tempfile
from collections import Counter
from pathlib import Path

HEADER = 17          # "BLENDER17-01v0500": the 64-bit block headers of Blender 5
BLOCK_HEADER = 32    # code (4), SDNA index (4), old address (8), length (8), count (8)


def blocks(buf: bytes) -> list[tuple[bytes, int, int]]:
    """(code, data offset, data length) of each file block."""
    if not buf.startswith(b"BLENDER17-01"):
        raise SystemExit(f"not a Blender 5 uncompressed .blend (header {buf[:17]!r})")
    out, off = [], HEADER
    while off < len(buf):
        code = buf[off:off + 4]
        length = struct.unpack("<q", buf[off + 16:off + 24])[0]
        out.append((code.rstrip(b"\0"), off + BLOCK_HEADER, length))
        off += BLOCK_HEADER + length
        if code == b"ENDB":
            break
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--prompt", default="a person walks forward")
    ap.add_argument("--seconds", type=float, default=4.0)
    args = ap.parse_args(argv)

    import bpy

    from shapemove.core.generation.loaded_generator import loaded_generator
    from shapemove.shapemove_addon.headless import build_scene_file

    gen = loaded_generator()
    motion = gen.generate(args.prompt, seconds=args.seconds, seed=0)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for k in range(2):
            build_scene_file(motion, gen.body, tmp / f"s{k}.blend", tmp / f"s{k}.png", frames=2, resolution=(160, 160))
            bpy.ops.wm.save_as_mainfile(filepath=str(tmp / f"raw{k}.blend"), compress=False, copy=True)
        same_png = (tmp / "s0.png").read_bytes() == (tmp / "s1.png").read_bytes()
        sizes = [(tmp / f"s{k}.blend").stat().st_size for k in range(2)]
        a, b = ((tmp / f"raw{k}.blend").read_bytes() for k in range(2))
    print(f"preview strips identical: {same_png}; compressed .blend: {sizes[0]:,} and {sizes[1]:,} bytes")
    if len(a) != len(b):
        print(f"uncompressed .blend: {len(a):,} and {len(b):,} bytes (different layouts)")
        return 0
    where, differing = Counter(), 0
    for (code, off, n), _ in zip(blocks(a), blocks(b)):
        d = sum(x != y for x, y in zip(a[off:off + n], b[off:off + n]))
        if d:
            where[code.decode("ascii", "replace")] += d
            differing += d
    print(f"uncompressed .blend: {differing:,} of {len(a):,} bytes differ, by block kind: "
          + ", ".join(f"{k} {v:,}" for k, v in where.most_common()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
