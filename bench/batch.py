"""A batch of prompts (``generate --prompts``, issue 55's targets), every ratio measured in one run:

- items per second with 2 worker processes against 1 on the same prompts (both start their
  workers, load the model and run the same items; each item's files are checked to be the same);
- per-item time in a warm worker (the items after the first, from the manifest's timings) against
  the same item generated alone in this process with the model loaded (the warm single prompt);
- a 10,000-line ``.jsonl`` read, checked and sharded (wall seconds; torch already imported).
Default: 8 prompts of 2 s with 1 candidate (``--quick``: 4). The machine is shared, so wall time
includes waiting for a core."""
from __future__ import annotations

import json
import tempfile
import time
from pathlib import Path

PROMPTS = ["a person walks forward", "someone waves with the right hand", "a person jumps", "a person squats",
           "a man runs forward", "a woman kicks with the left leg", "a person sits down", "someone turns around"]
SETTINGS = {"temperature": 1.0, "top_k": 50, "shape_from": "auto", "candidates": 1, "guidance": None,
            "retrieval_prefix": 2, "retrieved": 2, "retrieval_first": None, "retrieval": True, "parts": True,
            "library": None, "body_model": "openbody"}


def _batch(folder: Path, prompts: Path, jobs: int) -> tuple[float, list[dict]]:
    from ..core.batch.engines import ProcessPool
    from ..core.batch.generate_item import generate_item
    from ..core.batch.items import read_items
    from ..core.batch.manifest import read_manifest
    from ..core.batch.model_identity import model_identity
    from ..core.generation.model_bundle import resolve_model_dir
    from ..core.batch.runner import run_batch

    items, count = read_items(prompts, defaults={"seconds": 2.0})
    where = {"model": None, "library": None, "body_model": None}
    t0 = time.perf_counter()
    res = run_batch("generate", generate_item, items, count, SETTINGS, model_identity(resolve_model_dir()), where,
                    folder, ProcessPool(jobs), interval=1e9)
    wall = time.perf_counter() - t0
    if res.failed:
        raise RuntimeError(f"batch items failed: {res.failed}")
    return wall, sorted(read_manifest(res.manifest)[0], key=lambda r: r["item"])


def _read_10k(tmp: Path) -> float:
    from ..core.batch.items import read_items
    from ..core.batch.shard import parse_shard

    p = tmp / "10k.jsonl"
    with open(p, "w") as fh:
        for i in range(10_000):
            fh.write(json.dumps({"prompt": PROMPTS[i % len(PROMPTS)], "shape_text": "a tall man", "seconds": 2 + i % 5,
                                 "seed": i, "loop": i % 3 == 0}) + "\n")
    t0 = time.perf_counter()
    items, _ = read_items(p, parse_shard("1/4"))
    return time.perf_counter() - t0


def _warm_single(tmp: Path, spec: dict, repeats: int) -> float:
    from ..core.batch.generate_item import generate_item

    generate_item(spec, tmp)   # loads the model, warms the caches
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        generate_item(spec, tmp)
        best = min(best, time.perf_counter() - t0)
    return best


def run(quick: bool = False) -> dict:
    import torch  # noqa: F401  (imported before the 10k read: the CLI has it loaded by then)

    n = 4 if quick else 8
    with tempfile.TemporaryDirectory(prefix="shapemove_bench_batch_") as tmp:
        tmp = Path(tmp)
        prompts = tmp / "prompts.jsonl"
        prompts.write_text("".join(json.dumps({"prompt": PROMPTS[i % len(PROMPTS)]}) + "\n" for i in range(n)))
        one, recs1 = _batch(tmp / "jobs1", prompts, 1)
        two, recs2 = _batch(tmp / "jobs2", prompts, 2)
        same = [r["outputs"] for r in recs1] == [r["outputs"] for r in recs2]
        per_item = sorted(r["timing"]["seconds"] for r in recs1[1:])
        per_item = per_item[len(per_item) // 2]
        spec = {**{k: recs1[1][k] for k in ("options", "settings")}, "stem": "single",
                "where": {"model": None, "library": None, "body_model": None}}
        single = _warm_single(tmp, spec, 1 if quick else 2)
        read = _read_10k(tmp)
    speedup = one / two
    print(f"{n} prompts (2 s, 1 candidate): 1 worker {one:.1f} s ({n / one:.2f} items/s), 2 workers {two:.1f} s "
          f"({n / two:.2f} items/s): batch_jobs2_over_jobs1 {speedup:.2f}x (goal >= 1.6x); files identical: {same}")
    print(f"per item in a warm worker {per_item:.2f} s (median) vs the warm single prompt {single:.2f} s: "
          f"{per_item / single:.2f}x (goal <= 1.3x)")
    print(f"10,000-line .jsonl read, checked and sharded: {read:.2f} s (goal < 2 s)")
    return {"batch_items": n, "batch_jobs1_s": one, "batch_jobs2_s": two, "batch_jobs2_over_jobs1": speedup,
            "batch_jobs_identical": same, "batch_item_warm_s": per_item, "batch_single_warm_s": single,
            "batch_item_over_single": per_item / single, "batch_read_10k_s": read}
