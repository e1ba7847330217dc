"""`python -m shapemove search --library DIR --query TEXT [--top K] [--tma PATH]`.

Ranks the motions of DIR (a built dataset folder, or a folder of .npz/.bvh/.amc files) by their
TMA similarity to the query and prints a table. The embeddings are cached in DIR.
"""
from __future__ import annotations

from pathlib import Path

from ..core.search.motion_search import check_query, index_library, search


def add_arguments(p):
    p.add_argument("--library", type=Path, required=True, help="dataset folder or folder of .npz/.bvh/.amc motions")
    p.add_argument("--query", required=True, help="text describing the motion, e.g. 'a person waves'")
    p.add_argument("--top", type=int, default=10, help="how many results (default 10)")
    p.add_argument("--tma", type=Path, help="tma.pt or its run folder (default: the default model's)")
    p.add_argument("--no-cache", action="store_true", help="do not read or write the library's index cache")


def run(args) -> int:
    check_query(args.query, args.top)
    index = index_library(args.library, args.tma, use_cache=not args.no_cache)
    results = search(index, args.query, args.top)
    src = "cached index" if index.from_cache else "new index"
    print(f"{len(index)} motions in {args.library} ({src}); query: {args.query!r}")
    if index.skipped:
        print(f"skipped {len(index.skipped)} unreadable file(s), e.g. {index.skipped[0][0]}: {index.skipped[0][1]}")
    w = max(len("id"), *(len(r[0]) for r in results))
    print(f"{'rank':>4}  {'score':>6}  {'id':<{w}}  caption")
    for rank, (cid, score, path, caption) in enumerate(results, 1):
        print(f"{rank:>4}  {score:6.3f}  {cid:<{w}}  {caption or '-'}")
    return 0
