"""Batches of prompts (issue 55's targets), every ratio measured in one run:

- items per second with 2 worker processes against 1 on the same 40 prompts, for
  ``generate --prompts`` (4 s motions, the default 8 candidates) and for ``render`` (2 frames at
  160x160): both runs start their workers, load the model and run the same items, and each item's
  files are checked to be the same (the ``.blend`` excepted: docs/batches.md). Two ratios: over
  the whole batch (starting the workers included), and once every worker has finished its first
  item (the rate a long batch runs at; from the manifest's timings);
- per-item time in a warm worker (items 1 to 8 of the 1-worker generate batch, from the manifest's
  timings) against the same items generated in this process with the model loaded, one after
  another after item 0 as the worker ran them (the warm single prompt: the same work and caches
  without the pool, the hashing and the manifest);
- a 10,000-line ``.jsonl`` read, checked and sharded (wall seconds; torch already imported).
``--quick``: 8 prompts, generate only. The machine is shared, so wall time includes waiting for a
core: the load average is printed with the figures, and the CPU seconds of an item (the
manifest's ``timing.cpu_seconds``) with 1 and 2 workers and alone, which waiting does not count."""
from __future__ import annotations

import json
import os
import tempfile
import time
from datetime import datetime
from pathlib import Path

PROMPTS = ["a person walks forward", "someone waves with the right hand", "a person jumps", "a person squats",
           "a man runs forward", "a woman kicks with the left leg", "a person sits down", "someone turns around"]
SETTINGS = {"temperature": 1.0, "top_k": 50, "shape_from": "auto", "candidates": 8, "guidance": None,
            "retrieval_prefix": 2, "retrieved": 2, "retrieval_first": None, "retrieval": True, "parts": True,
            "library": None, "body_model": "openbody"}
RENDER = {"frames": 2, "resolution": [160, 160], "video": False}
SECONDS = 4.0
SAME_ITEMS = 8


def _finished_at(rec: dict) -> float:
    started = datetime.fromisoformat(rec["timing"]["started"].replace("Z", "+00:00")).timestamp()
    return started + rec["timing"]["seconds"]


def warm_rate(records: list[dict]) -> float:
    """Items per second once every worker has finished its first item: the items finished after
    that moment over the time from it to the last finish."""
    firsts: dict = {}
    for r in records:
        w = r["timing"]["worker"]
        firsts[w] = min(firsts.get(w, float("inf")), _finished_at(r))
    t0 = max(firsts.values())
    ends = [_finished_at(r) for r in records if _finished_at(r) > t0]
    return len(ends) / (max(ends) - t0) if ends else float("nan")


def _batch(kind: str, folder: Path, prompts: Path, jobs: int) -> tuple[float, list[dict]]:
    from ..core.batch.engines import ProcessPool
    from ..core.batch.items import LINE_KEYS, read_items
    from ..core.batch.manifest import read_manifest
    from ..core.batch.model_identity import model_identity
    from ..core.batch.runner import run_batch
    from ..core.generation.model_bundle import resolve_model_dir

    if kind == "render":
        from ..cli.render_item import render_item as task

        items, count = read_items(prompts, defaults={"seconds": SECONDS}, keys=(*LINE_KEYS, "root_motion"))
        settings = {**SETTINGS, **RENDER}
    else:
        from ..core.batch.generate_item import generate_item as task

        items, count = read_items(prompts, defaults={"seconds": SECONDS})
        settings = SETTINGS
    where = {"model": None, "library": None, "body_model": None}
    t0 = time.perf_counter()
    res = run_batch(kind, task, items, count, settings, model_identity(resolve_model_dir()), where, folder,
                    ProcessPool(jobs), interval=1e9)
    wall = time.perf_counter() - t0
    if res.failed:
        raise RuntimeError(f"batch items failed: {res.failed}")
    return wall, sorted(read_manifest(res.manifest)[0], key=lambda r: r["item"])


def _same_files(a: list[dict], b: list[dict]) -> bool:
    def files(recs):
        return [[(e["file"], e["sha256"]) for e in r["outputs"] if not e["file"].endswith(".blend")] for r in recs]

    return files(a) == files(b)


def _read_10k(tmp: Path) -> float:
    from ..core.batch.items import read_items
    from ..core.batch.shard import parse_shard

    p = tmp / "10k.jsonl"
    with open(p, "w") as fh:
        for i in range(10_000):
            fh.write(json.dumps({"prompt": PROMPTS[i % len(PROMPTS)], "shape_text": "a tall man", "seconds": 2 + i % 5,
                                 "seed": i, "loop": i % 3 == 0}) + "\n")
    t0 = time.perf_counter()
    read_items(p, parse_shard("1/4"))
    return time.perf_counter() - t0


def _alone(tmp: Path, records: list[dict]) -> list[tuple[float, float]]:
    """(wall s, CPU s) of each record's item generated in this process, one after another as the
    worker ran them (the first loads the model and is not timed): the same work and caches, without
    the pool, the hashing and the manifest."""
    from ..core.batch.generate_item import generate_item

    where = {"model": None, "library": None, "body_model": None}
    times = []
    for r in records:
        t0, c0 = time.perf_counter(), time.process_time()
        generate_item({"options": r["options"], "settings": r["settings"], "stem": "alone", "where": where}, tmp)
        times.append((time.perf_counter() - t0, time.process_time() - c0))
    return times[1:]


def _cpu_per_item(records: list[dict]) -> float:
    """Mean CPU seconds of an item after each worker's first (which loads the model)."""
    firsts = {}
    for r in sorted(records, key=_finished_at):
        firsts.setdefault(r["timing"]["worker"], r["item"])
    cpu = [r["timing"]["cpu_seconds"] for r in records if r["item"] not in firsts.values()]
    return sum(cpu) / len(cpu)


def _two_against_one(kind: str, tmp: Path, prompts: Path, n: int, goal: float) -> dict:
    one, recs1 = _batch(kind, tmp / f"{kind}1", prompts, 1)
    two, recs2 = _batch(kind, tmp / f"{kind}2", prompts, 2)
    same = _same_files(recs1, recs2)
    whole, warm = one / two, warm_rate(recs2) / warm_rate(recs1)
    print(f"{kind}, {n} prompts: 1 worker {one:.1f} s ({n / one:.2f} items/s), 2 workers {two:.1f} s "
          f"({n / two:.2f} items/s): {whole:.2f}x over the whole batch; once the workers are warm "
          f"{warm_rate(recs1):.2f} -> {warm_rate(recs2):.2f} items/s, {warm:.2f}x (goal >= {goal}x); "
          f"files identical: {same}; CPU per item {_cpu_per_item(recs1):.2f} s with 1 worker, "
          f"{_cpu_per_item(recs2):.2f} s with 2   [load average {os.getloadavg()[0]:.1f}]")
    return {f"batch_{kind}_jobs1_s": one, f"batch_{kind}_jobs2_s": two, f"batch_{kind}_jobs2_over_jobs1": whole,
            f"batch_{kind}_warm_jobs2_over_jobs1": warm, f"batch_{kind}_identical": same,
            f"batch_{kind}_cpu_per_item_jobs1_s": _cpu_per_item(recs1),
            f"batch_{kind}_cpu_per_item_jobs2_s": _cpu_per_item(recs2)}, recs1


def run(quick: bool = False) -> dict:
    import torch  # noqa: F401  (imported before the 10k read: the CLI has it loaded by then)

    n = 8 if quick else 40
    print(f"load average at the start {os.getloadavg()[0]:.1f} ({os.cpu_count()} cores)")
    out: dict = {"batch_items": n}
    with tempfile.TemporaryDirectory(prefix="shapemove_bench_batch_") as tmp:
        tmp = Path(tmp)
        prompts = tmp / "prompts.jsonl"
        prompts.write_text("".join(json.dumps({"prompt": PROMPTS[i % len(PROMPTS)]}) + "\n" for i in range(n)))
        got, recs1 = _two_against_one("generate", tmp, prompts, n, 1.6)
        out.update(got)
        if not quick:
            out.update(_two_against_one("render", tmp, prompts, n, 1.5)[0])
        warm = recs1[1:1 + SAME_ITEMS]          # items after the worker's first, against the same items alone
        per_item = sum(r["timing"]["seconds"] for r in warm)
        per_item_cpu = sum(r["timing"]["cpu_seconds"] for r in warm)
        alone = _alone(tmp, recs1[:1 + SAME_ITEMS])
        single, single_cpu = sum(a[0] for a in alone), sum(a[1] for a in alone)
        read = _read_10k(tmp)
    print(f"items 1-{len(warm)} in a warm worker {per_item:.2f} s ({per_item_cpu:.2f} CPU s) vs the same prompts "
          f"in this process after item 0 {single:.2f} s ({single_cpu:.2f} CPU s): {per_item / single:.2f}x wall, "
          f"{per_item_cpu / single_cpu:.2f}x CPU (goal <= 1.3x)")
    print(f"10,000-line .jsonl read, checked and sharded: {read:.2f} s (goal < 2 s)   "
          f"[load average {os.getloadavg()[0]:.1f}]")
    out.update({"batch_item_warm_s": per_item, "batch_single_warm_s": single,
                "batch_item_over_single": per_item / single, "batch_item_over_single_cpu": per_item_cpu / single_cpu,
                "batch_read_10k_s": read})
    return out
