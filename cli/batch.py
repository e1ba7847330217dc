"""`python -m shapemove batch merge MANIFEST... --out DIR`: join the manifests of a batch's shards
(``generate --prompts`` or ``render`` run with ``--shard I/N``, on one machine or many) into one
folder with one ``manifest.jsonl``, refusing items that disagree (docs/batches.md)."""
from __future__ import annotations

from pathlib import Path


def add_arguments(p):
    sub = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    m = sub.add_parser("merge", help="join shards' manifests (and copy their files) into one folder",
                       description="join shards' manifests (and copy their files) into one folder")
    m.add_argument("manifests", type=Path, nargs="+", help="manifest.jsonl / manifest-I-of-N.jsonl files")
    m.add_argument("--out", type=Path, required=True, help="the folder of the merged batch")


def run(args) -> int:
    from ..core.batch.merge import merge_manifests

    res = merge_manifests(args.manifests, args.out)
    total = f" of {res.of}" if res.of is not None else ""
    print(f"merged {res.items}{total} items ({res.failed} failed, {res.copied} files copied) into {res.manifest}")
    if res.missing:
        shown = ", ".join(map(str, res.missing[:20])) + (" ..." if len(res.missing) > 20 else "")
        print(f"  missing items (no shard has them): {shown}")
    return 0 if not res.missing else 1
