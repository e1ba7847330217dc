"""Batches of prompts (issue 55's targets), every ratio measured in one run:

- items per second with ``--jobs 2`` against ``--jobs 1`` on the same 40 prompts, for
  ``generate --prompts`` (4 s motions, the default 8 candidates) and for ``render`` (2 frames at
  160x160), each the command run as a user runs it (a new process that loads the model, and with
  ``--jobs 2`` starts two workers that each load it) on the same items, and each item's
  files are checked to be the same (the ``.blend`` excepted: docs/batches.md). Two ratios: over
  the whole batch (starting the workers included), and once every worker has finished its first
  item (the rate a long batch runs at; from the manifest's timings);
- per-item time in a warm batch (items 1 to 8 of the `--jobs 1` generate batch, from the manifest's
  timings) against the same items generated in this process with the model loaded, one after
  another after item 0 as the worker ran them (the warm single prompt: the same work and caches
  without the pool, the hashing and the manifest);
- a 10,000-line ``.jsonl`` read, checked and sharded (wall seconds; torch already imported).
``--quick``: 8 prompts, generate only. The machine is shared, so wall time includes waiting for a
core: the load average is printed with the figures, the CPU seconds of an item (the manifest's
``timing.cpu_seconds``) with 1 and 2 workers and alone, which waiting does not count, and the
cores the warm batch got (items per second x CPU seconds per item)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from datetime import datetime
from pathlib import Path

PROMPTS = ["a person walks forward", "someone waves with the right hand", "a person jumps", "a person squats",
           "a man runs forward", "a woman kicks with the left leg", "a person sits down", "someone turns around"]
CANDIDATES = 8
RENDER = {"frames": 2, "resolution": [160, 160]}
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
    """(wall seconds, records by item) of ``generate``/``render --prompts PROMPTS --jobs JOBS`` run
    as a user runs it, in a new process."""
    from ..core.batch.manifest import read_manifest

    extra = ["--candidates", str(CANDIDATES)] if kind == "generate" else \
        ["--frames", str(RENDER["frames"]), "--resolution", *map(str, RENDER["resolution"])]
    cmd = [sys.executable, "-m", "shapemove", kind, "--prompts", str(prompts), "--out", str(folder),
           "--jobs", str(jobs), *extra]
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, env={**os.environ, "TQDM_DISABLE": "1"})
    wall = time.perf_counter() - t0
    records = sorted(read_manifest(folder / "manifest.jsonl")[0], key=lambda r: r["item"])
    if res.returncode != 0 or any(r["status"] != "done" for r in records):
        raise RuntimeError(f"{' '.join(cmd)} failed ({res.returncode}): {res.stderr.strip()[-800:]}")
    return wall, records


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
    # items per second x CPU seconds per item: the cores the batch had (all of them, 2 here, when idle)
    cores1, cores2 = warm_rate(recs1) * _cpu_per_item(recs1), warm_rate(recs2) * _cpu_per_item(recs2)
    print(f"{kind}, {n} prompts: --jobs 1 {one:.1f} s ({n / one:.2f} items/s), --jobs 2 {two:.1f} s "
          f"({n / two:.2f} items/s): {whole:.2f}x over the whole batch; once the workers are warm "
          f"{warm_rate(recs1):.2f} -> {warm_rate(recs2):.2f} items/s, {warm:.2f}x (goal >= {goal}x); "
          f"files identical: {same}; CPU per item {_cpu_per_item(recs1):.2f} s with --jobs 1, "
          f"{_cpu_per_item(recs2):.2f} s with 2; cores the warm batch got {cores1:.2f} and {cores2:.2f}   "
          f"[load average {os.getloadavg()[0]:.1f}]")
    return {f"batch_{kind}_jobs1_s": one, f"batch_{kind}_jobs2_s": two, f"batch_{kind}_jobs2_over_jobs1": whole,
            f"batch_{kind}_warm_jobs2_over_jobs1": warm, f"batch_{kind}_identical": same,
            f"batch_{kind}_cpu_per_item_jobs1_s": _cpu_per_item(recs1),
            f"batch_{kind}_cpu_per_item_jobs2_s": _cpu_per_item(recs2), f"batch_{kind}_cores_jobs1": cores1,
            f"batch_{kind}_cores_jobs2": cores2}, recs1


def run(quick: bool = False) -> dict:
    import torch  # noqa: F401  (imported before the 10k read: the CLI has it loaded by then)

    n = 8 if quick else 40
    print(f"load average at the start {os.getloadavg()[0]:.1f} ({os.cpu_count()} cores)")
    out: dict = {"batch_items": n}
    with tempfile.TemporaryDirectory(prefix="shapemove_bench_batch_") as tmp:
        tmp = Path(tmp)
        prompts = tmp / "prompts.jsonl"
        prompts.write_text("".join(json.dumps({"prompt": PROMPTS[i % len(PROMPTS)], "seconds": SECONDS}) + "\n"
                                   for i in range(n)))
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
    print(f"items 1-{len(warm)} in the warm --jobs 1 batch {per_item:.2f} s ({per_item_cpu:.2f} CPU s) vs the "
          f"same prompts in this process after item 0 {single:.2f} s ({single_cpu:.2f} CPU s): "
          f"{per_item / single:.2f}x wall, {per_item_cpu / single_cpu:.2f}x CPU (goal <= 1.3x)")
    print(f"10,000-line .jsonl read, checked and sharded: {read:.2f} s (goal < 2 s)   "
          f"[load average {os.getloadavg()[0]:.1f}]")
    out.update({"batch_item_warm_s": per_item, "batch_single_warm_s": single,
                "batch_item_over_single": per_item / single, "batch_item_over_single_cpu": per_item_cpu / single_cpu,
                "batch_read_10k_s": read})
    return out
