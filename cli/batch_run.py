"""What ``generate --prompts`` and ``render`` share for a batch (docs/batches.md): the options
``--jobs``, ``--shard``, ``--dask``; the engine they choose; the settings every item gets; the
summary printed at the end."""
from __future__ import annotations

from pathlib import Path

from ..core.errors import ShapeMoveError


def add_batch_arguments(p) -> None:
    g = p.add_argument_group("batch (docs/batches.md)")
    g.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="worker processes on this machine, each loading the model once (default 1: this process)")
    g.add_argument("--shard", default=None, metavar="I/N",
                   help="only every N-th item from item I (0-based), for N machines sharing a batch; "
                        "join the shards with `batch merge`")
    g.add_argument("--dask", default=None, metavar="ADDRESS",
                   help="run the items on a Dask distributed cluster (scheduler address, e.g. tcp://host:8786)")


def engine_of(args, preload=None):
    """The engine ``--jobs`` / ``--dask`` ask for; ``preload``: what workers forked from this process
    start with (``engines.ProcessPool``)."""
    from ..core.batch.engines import DaskCluster, InProcess, ProcessPool

    if args.dask and args.jobs != 1:
        raise ShapeMoveError("give --jobs or --dask, not both (a Dask cluster has its own workers)")
    if args.dask:
        return DaskCluster(args.dask)
    if args.jobs < 1:
        raise ShapeMoveError(f"--jobs takes a number of worker processes >= 1, got {args.jobs}")
    return InProcess() if args.jobs == 1 else ProcessPool(args.jobs, preload)


def sampling_settings(args) -> dict:
    """The sampling settings of every item (``generate``'s options; ``render`` has the defaults)."""
    from ..core.generation.sampling_params import (DEFAULT_CANDIDATES, DEFAULT_RETRIEVAL_FIRST,
                                                   DEFAULT_RETRIEVAL_PREFIX, DEFAULT_RETRIEVED, check_candidates,
                                                   check_guidance, check_retrieval_first, check_retrieval_prefix,
                                                   check_retrieved, check_sampling)

    def given(name, default):
        v = getattr(args, name, None)
        return default if v is None else v

    _, temperature, top_k = check_sampling(0, given("temperature", 1.0), given("top_k", 50))
    return {"temperature": temperature, "top_k": top_k, "shape_from": given("shape_from", "auto"),
            "candidates": check_candidates(given("candidates", DEFAULT_CANDIDATES)),
            "guidance": check_guidance(getattr(args, "guidance", None)),
            "retrieval_prefix": check_retrieval_prefix(given("retrieval_prefix", DEFAULT_RETRIEVAL_PREFIX)),
            "retrieved": check_retrieved(given("retrieved", DEFAULT_RETRIEVED)),
            "retrieval_first": check_retrieval_first(given("retrieval_first", DEFAULT_RETRIEVAL_FIRST)),
            "retrieval": not getattr(args, "no_retrieval", False), "parts": not getattr(args, "no_parts", False),
            "captured": not getattr(args, "no_library", False)}


def where_of(args) -> tuple[dict, dict, dict]:
    """(paths for the workers, what the manifest names of them, the model's identity)."""
    from ..core.batch.model_identity import model_identity
    from ..core.generation.model_bundle import resolve_model_dir

    model_dir = resolve_model_dir(args.model)
    library = getattr(args, "library", None)
    body = getattr(args, "body_model", None)
    where = {"model": str(Path(args.model).resolve()) if args.model else None,
             "library": str(Path(library).resolve()) if library else None,
             "body_model": str(Path(body).resolve()) if body and body != "openbody" else body}
    named = {"library": Path(library).name if library else None,
             "body_model": Path(body).name if body and body != "openbody" else (body or "openbody")}
    return where, named, model_identity(model_dir)


def run_and_report(kind: str, task, args, items, count: int, settings: dict, where: dict, model: dict,
                   shard) -> int:
    from ..core.batch.runner import run_batch

    preload = None
    if kind == "generate":   # workers forked from a process with the model loaded (no Blender here)
        from functools import partial

        from ..core.batch.generate_item import warm_generator

        preload = partial(warm_generator, where)
    engine = engine_of(args, preload)
    try:
        res = run_batch(kind, task, items, count, settings, model, where, args.out, engine, shard)
    except KeyboardInterrupt:
        print(f"interrupted: the finished items are in {args.out}; run the same command again to go on")
        return 130
    verb = "rendered" if kind == "render" else "generated"
    print(f"{verb} {res.skipped + res.done} of {res.total} prompts into {args.out} ({res.skipped} done before this "
          f"run, {len(res.failed)} failed); manifest {res.manifest}")
    for item, label, why in res.failed:
        print(f"  failed: item {item} {label!r}: {why}")
    return 0 if not res.failed or res.done + res.skipped else 1
