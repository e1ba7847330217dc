"""Where a batch's items run. Each engine's ``run(task, specs, folder)`` yields the items' records
as they finish (in any order); the caller is the one manifest writer.

- ``InProcess``: one after another in this process (``--jobs 1``).
- ``ProcessPool(jobs, preload)``: ``jobs`` worker processes, each on cores / jobs torch threads;
  an item is handed out when a worker frees up (at most two per worker queued); workers write
  their files into the batch folder. With a ``preload`` (``generate --prompts``: load the model),
  this process runs it once on one torch thread and the workers are forked from it, so they start
  with the model loaded (no OpenMP thread pool exists yet to be lost in the fork; tokenizers'
  threads are turned off); without one (``render``: bpy) or where fork does not exist, they are
  spawned, and each imports torch and loads the model on its first item and keeps it (the task
  caches it per process).
- ``DaskCluster(address)``: items as tasks on a running Dask distributed cluster; a task returns its
  files' bytes (``item_run.run_remote``) and they are written here, so the workers need no shared
  disk, only this package and the model folder (the default model ships inside the package).
Ctrl-C stops handing out items; what finished is in the manifest.
"""
from __future__ import annotations

import os
import signal
import sys
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from itertools import islice
from pathlib import Path

from ..atomic import atomic_write_bytes
from ..errors import ShapeMoveError
from .item_run import run_item, run_remote
from .outputs import sha256_of

QUEUED_PER_WORKER = 2


class InProcess:
    jobs = 1

    def run(self, task, specs, folder):
        for spec in specs:
            yield run_item(task, spec, folder)


def _watch_parent(parent: int) -> None:
    """A worker whose batch process died (kill -9) exits instead of running on orphaned."""
    while True:
        time.sleep(1.0)
        if os.getppid() != parent:
            os._exit(1)


def _blender_script_path(entry: str) -> bool:
    parts = Path(entry).parts
    return "scripts" in parts and ("bpy" in parts or "blender" in parts)


def cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:   # not on Linux
        return os.cpu_count() or 1


def threads_per_worker(jobs: int) -> int:
    """Each of ``jobs`` workers runs torch (and its BLAS) on cores / jobs threads, so N workers
    share the cores without oversubscribing them, and one worker (or ``--jobs 1``, this process,
    torch's default) has them all."""
    return max(1, cores() // jobs)


def _init_worker(threads: int, parent: int) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)   # Ctrl-C is the batch process's: it stops handing out items
    for name in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
        os.environ[name] = str(threads)
    # a parent that imported bpy passes on the script folders bpy put on sys.path; their `bpy`
    # package would shadow the module here ("No module named '_bpy'"): bpy adds them again on import
    sys.path[:] = [p for p in sys.path if not _blender_script_path(p)]
    os.environ.setdefault("TQDM_DISABLE", "1")
    import torch

    torch.set_num_threads(threads)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


def start_method(preload) -> str:
    """"fork" for workers that start from this process's ``preload`` (where fork exists and bpy is
    not loaded here), else "spawn"."""
    import multiprocessing

    forks = "fork" in multiprocessing.get_all_start_methods() and "bpy" not in sys.modules
    return "fork" if preload is not None and forks else "spawn"


class ProcessPool:
    def __init__(self, jobs: int, preload=None):
        if not 1 <= jobs <= 256:
            raise ShapeMoveError(f"--jobs takes 1 to 256 worker processes, got {jobs}")
        self.jobs, self.preload = jobs, preload

    def run(self, task, specs, folder):
        import multiprocessing

        threads = threads_per_worker(self.jobs)
        method = start_method(self.preload)
        if method == "fork":
            from ..torch_threads import one_torch_thread

            os.environ["TOKENIZERS_PARALLELISM"] = "false"   # its threads do not survive a fork either
            with one_torch_thread():
                self.preload()
        pool = ProcessPoolExecutor(self.jobs, mp_context=multiprocessing.get_context(method),
                                   initializer=_init_worker, initargs=(threads, os.getpid()))
        specs, running = iter(specs), set()
        try:
            while True:
                while len(running) < self.jobs * QUEUED_PER_WORKER:
                    spec = next(specs, None)
                    if spec is None:
                        break
                    running.add(pool.submit(run_item, task, spec, str(folder)))
                if not running:
                    return
                finished, running = wait(running, return_when=FIRST_COMPLETED)
                for fut in finished:
                    try:
                        yield fut.result()
                    except BrokenProcessPool:
                        raise ShapeMoveError("a worker process died (out of memory, or killed); the items "
                                             "finished so far are in the manifest: run the same command again "
                                             "to go on") from None
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


class DaskCluster:
    def __init__(self, address: str, timeout: float = 30.0):
        try:
            from distributed import Client
        except ImportError:
            raise ShapeMoveError("--dask needs Dask distributed: pip install distributed") from None
        try:
            self.client = Client(address, timeout=timeout, set_as_default=False)
        except Exception as exc:  # noqa: BLE001  (OSError, TimeoutError, a malformed address: one sentence)
            raise ShapeMoveError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
        self.jobs = max(1, sum(w.get("nthreads", 1) for w in self.client.scheduler_info()["workers"].values()))

    def run(self, task, specs, folder):
        from distributed import as_completed

        specs = iter(specs)

        def submit(spec):
            return self.client.submit(run_remote, task, spec, pure=False)

        first = [submit(spec) for spec in islice(specs, self.jobs * QUEUED_PER_WORKER)]
        if not first:
            self.client.close()
            return
        ac = as_completed(first, loop=self.client.loop)

        def submit_next() -> None:
            spec = next(specs, None)
            if spec is not None:
                ac.add(submit(spec))

        try:
            for fut in ac:
                try:
                    record, blobs = fut.result()
                except Exception as exc:  # noqa: BLE001  (workers lost past Dask's retries)
                    raise ShapeMoveError(f"the Dask cluster could not run an item ({type(exc).__name__}: {exc}); "
                                         "the items finished so far are in the manifest: run the same command "
                                         "again to go on") from None
                for e in record["outputs"]:
                    path = Path(folder) / e["file"]
                    atomic_write_bytes(path, blobs[e["file"]])
                    if sha256_of(path) != e["sha256"]:
                        raise ShapeMoveError(f"{path}: the bytes written differ from the worker's (disk problem?)")
                fut.release()
                yield record
                submit_next()
        finally:
            for fut in list(ac.futures):
                fut.cancel()
            self.client.close()
