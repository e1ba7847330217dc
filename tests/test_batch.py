"""Batches (docs/batches.md, core/batch/): the prompts file read, checked and sharded; the manifest's
lines; resume after kill -9 at five random moments; --jobs 2, shards + merge and a Dask cluster giving the same files,
byte for byte, as one process. Real generation with the default model: 1 s motions, 1 candidate."""
from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import need_module

from shapemove.core.batch.items import read_items
from shapemove.core.batch.manifest import comparable, read_manifest
from shapemove.core.batch.shard import parse_shard
from shapemove.core.errors import ShapeMoveError

ROOT = Path(__file__).resolve().parents[1]
FAST = ["--seconds", "1", "--candidates", "1"]
LINES = [{"prompt": "a person walks forward"},
         {"prompt": "someone waves with the right hand", "shape_text": "a tall, heavy-set man"},
         {"prompt": "a person jumps", "seed": 7, "betas": [1.5, -0.5]},
         {"prompt": "a person walks forward", "seconds": 500},          # refused by the generator: a failed item
         {"prompt": "a person squats", "in_place": True}]


def cli(*argv) -> int:
    from shapemove.cli import main

    return main([str(a) for a in argv])


def sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def prompts(tmp_path_factory) -> Path:
    p = tmp_path_factory.mktemp("prompts") / "batch.jsonl"
    p.write_text("".join(json.dumps(ln) + "\n" for ln in LINES))
    return p


@pytest.fixture(scope="module")
def one_process(prompts, tmp_path_factory) -> Path:
    """The batch run in this process (--jobs 1): the reference the other engines must match."""
    out = tmp_path_factory.mktemp("jobs1")
    assert cli("generate", "--prompts", prompts, "--out", out, *FAST) == 0
    return out


def records(folder: Path, name: str = "manifest.jsonl") -> dict:
    recs, skipped = read_manifest(folder / name)
    assert skipped == 0
    return {r["item"]: r for r in recs}


# -- reading ---------------------------------------------------------------------------------

def test_items_are_read_checked_and_sharded(tmp_path):
    txt = tmp_path / "p.txt"
    txt.write_text("# a comment\na person walks forward\n\nsomeone waves\na person jumps\n")
    items, count = read_items(txt, defaults={"seconds": 2.0, "seed": 10})
    assert count == 3 and [it.line for it in items] == [2, 4, 5]
    assert [it.options["seed"] for it in items] == [10, 11, 12]          # base seed + item index
    assert items[1].stem == "001_someone_waves" and items[0].options["seconds"] == 2.0
    shards = [read_items(txt, parse_shard(f"{i}/2"))[0] for i in range(2)]
    assert [it.index for it in shards[0]] == [0, 2] and [it.index for it in shards[1]] == [1]

    bad = tmp_path / "bad.jsonl"
    bad.write_text('{"prompt": "a person walks"}\n{"prompt": "a person runs", "secs": 3}\n')
    with pytest.raises(ShapeMoveError, match=r"bad.jsonl:2: unknown key 'secs'"):
        read_items(bad)
    bad.write_text('{"prompt": "a person walks", "loop": true, "path": [[0, 0], [0, 2]]}\n')
    with pytest.raises(ShapeMoveError, match=r":1: --loop and --path do not go together"):
        read_items(bad)
    for text in ("1/1/1", "2/2", "x"):
        with pytest.raises(ShapeMoveError, match="--shard"):
            parse_shard(text)


def test_ten_thousand_lines_read_checked_and_sharded_in_under_two_seconds(tmp_path):
    p = tmp_path / "big.jsonl"
    with open(p, "w") as fh:
        for i in range(10_000):
            fh.write(json.dumps({"prompt": f"a person walks forward {i}", "shape_text": "a tall man",
                                 "seconds": 2 + i % 5, "seed": i}) + "\n")
    t0 = time.perf_counter()
    items, count = read_items(p, parse_shard("3/8"))
    dt = time.perf_counter() - t0
    assert count == 10_000 and len(items) == 1250 and items[0].index == 3 and items[-1].index == 9_995
    assert dt < 2.0, f"{dt:.2f} s"


# -- one process: the manifest, resume ------------------------------------------------------------

def test_the_manifest_says_what_made_each_file(one_process):
    from shapemove.core.scene.motion_file import load_motion

    recs = records(one_process)
    assert sorted(recs) == [0, 1, 2, 3, 4]
    model_sha = hashlib.sha256((ROOT / "weights" / "default" / "manifest.json").read_bytes()).hexdigest()
    for i, r in recs.items():
        assert r["model"]["manifest_sha256"] == model_sha and r["input"] == LINES[i] and r["of"] == 5
        assert r["settings"]["candidates"] == 1 and r["timing"]["seconds"] > 0
    failed = recs[3]
    assert failed["status"] == "failed" and "--seconds must be between" in failed["error"] and failed["outputs"] == []
    assert recs[2]["options"]["seed"] == 7 and recs[1]["options"]["seed"] == 1
    assert recs[2]["options"]["betas"][:3] == [1.5, -0.5, 0.0]
    for i in (0, 1, 2, 4):
        r = recs[i]
        assert r["status"] == "done" and r["error"] is None and r["source"]["kind"] == ("captured" if (r["source"]["provenance"] or "").startswith("captured") else "retrieved" if r["source"]["retrieved_clips"] else "generated")
        (out,) = r["outputs"]
        f = one_process / out["file"]
        assert out["sha256"] == sha(f) and out["bytes"] == f.stat().st_size
        m = load_motion(f)
        assert m.num_frames == r["result"]["frames"] == 20
        assert [round(float(b), 6) for b in m.betas] == r["result"]["betas"]
    assert recs[2]["result"]["betas"][:2] == [1.5, -0.5] and recs[2]["result"]["shape_source"] == "given"
    assert recs[4]["options"]["in_place"] is True


def test_a_second_run_redoes_only_what_is_not_done(one_process, prompts):
    before = records(one_process)
    (one_process / before[1]["outputs"][0]["file"]).write_bytes(b"damaged")   # a file that no longer matches
    assert cli("generate", "--prompts", prompts, "--out", one_process, *FAST) == 0
    after = records(one_process)
    lines = (one_process / "manifest.jsonl").read_text().splitlines()
    assert sorted(r["item"] for r in map(json.loads, lines)) == [0, 1, 2, 3, 4]   # each item once
    for i in (0, 2, 4):
        assert after[i] == before[i]                       # not redone: the same timing too
    assert after[1]["timing"] != before[1]["timing"] and comparable(after[1]) == comparable(before[1])
    assert after[3]["status"] == "failed" and after[3]["timing"] != before[3]["timing"]   # failed: tried again


KILL_PROMPTS = ["a person walks forward", "someone waves", "a person jumps", "a person squats", "a man runs forward",
                "a person kicks", "a person sits down", "someone turns around", "a person claps", "a person bows",
                "a person walks backward", "someone raises both arms", "a person stretches", "someone nods",
                "a person spins around", "a person crouches", "a man jogs forward", "a woman waves both hands",
                "a person hops", "a person throws a ball", "someone sidesteps to the left", "a person punches",
                "a man climbs stairs", "a person lies down"]   # more than five short runs can finish


def _valid_records(manifest: Path) -> int:
    return len(read_manifest(manifest)[0])


def test_kill_9_at_five_random_moments_then_resume(tmp_path):
    """One batch killed (kill -9, the whole process group) at five random moments, each somewhere
    in the item after the run's first (seeded: the kill lands in a generation, a file's write, a
    manifest line's write ...), then run to the end: every item once in the manifest, every listed
    file as listed, nothing redone that a killed run had done (its record and file untouched),
    and no file under a finished name that is not complete and listed."""
    import random

    prompts = tmp_path / "prompts.txt"
    prompts.write_text("\n".join(KILL_PROMPTS) + "\n")
    out, manifest = tmp_path / "killed", tmp_path / "killed" / "manifest.jsonl"
    argv = ["generate", "--prompts", prompts, "--out", out, "--seconds", "0.5", "--candidates", "1"]
    env = dict(os.environ, TQDM_DISABLE="1", OMP_NUM_THREADS="1")
    rng = random.Random(55)
    done_seen: dict = {}       # item -> its done record as a killed run left it
    done_mtime: dict = {}      # file -> its time as a killed run left it (a redo would rewrite it)
    finished: dict = {}        # file under a finished name after a kill -> its SHA-256
    for kill in range(5):
        before = _valid_records(manifest)
        proc = subprocess.Popen([sys.executable, "-m", "shapemove", *map(str, argv)], cwd=ROOT.parent, env=env,
                                start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.time() + 120
        while time.time() < deadline and proc.poll() is None and _valid_records(manifest) <= before:
            time.sleep(0.02)
        time.sleep(rng.uniform(0.0, 0.6))
        assert proc.poll() is None, f"kill {kill}: the run ended before it was killed"
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        recs, torn = read_manifest(manifest)
        assert torn <= 1                                   # at most the line being written
        for r in recs:
            if r["status"] == "done":
                assert done_seen.setdefault(r["item"], r) == r, f"item {r['item']} was redone"
                for e in r["outputs"]:
                    done_mtime.setdefault(e["file"], (out / e["file"]).stat().st_mtime_ns)
        for p in out.iterdir():
            if p.name != "manifest.jsonl" and ".tmp" not in p.name:
                finished.setdefault(p.name, sha(p))
    assert 5 <= len(done_seen) < len(KILL_PROMPTS)         # each run got somewhere; the last kill came before the end

    assert cli(*argv) == 0
    after = records(out)
    lines = manifest.read_text().splitlines()
    assert sorted(json.loads(ln)["item"] for ln in lines) == list(range(len(KILL_PROMPTS)))   # each item once
    for i, r in done_seen.items():
        assert after[i] == r                               # not redone: the same record, timing and all
    listed = {}
    for r in after.values():
        assert r["status"] == "done"
        for e in r["outputs"]:
            assert sha(out / e["file"]) == e["sha256"] and (out / e["file"]).stat().st_size == e["bytes"]
            listed[e["file"]] = e["sha256"]
    for name, t in done_mtime.items():
        assert (out / name).stat().st_mtime_ns == t        # the file a killed run finished was not written again
    assert {p.name for p in out.iterdir()} == {*listed, "manifest.jsonl"}   # no stray or temporary file
    for name, h in finished.items():
        assert listed[name] == h                           # what looked finished after a kill was complete


# -- other engines: the same files ---------------------------------------------------------------

def same_batch(folder: Path, ref: Path, name: str = "manifest.jsonl") -> None:
    got, want = records(folder, name), records(ref)
    assert sorted(got) == sorted(want)
    for i in want:
        assert comparable(got[i]) == comparable(want[i]), i
        for e in want[i]["outputs"]:
            assert (folder / e["file"]).read_bytes() == (ref / e["file"]).read_bytes()


@pytest.fixture(scope="module")
def two_processes(prompts, tmp_path_factory) -> Path:
    """The batch run by two worker processes (--jobs 2)."""
    out = tmp_path_factory.mktemp("jobs2")
    assert cli("generate", "--prompts", prompts, "--out", out, "--jobs", "2", *FAST) == 0
    return out


def test_two_worker_processes_give_the_same_files(two_processes, one_process):
    same_batch(two_processes, one_process)
    workers = {r["timing"]["worker"] for r in records(two_processes).values()}
    assert len(workers) == 2 and f":{os.getpid()}" not in " ".join(workers)


def test_shards_merge_into_the_whole_batch(prompts, tmp_path, one_process):
    shared = tmp_path / "shared"          # two shards writing into one folder
    for i in range(2):
        assert cli("generate", "--prompts", prompts, "--out", shared, "--shard", f"{i}/2", *FAST) == 0
    assert sorted(records(shared, "manifest-0-of-2.jsonl")) == [0, 2, 4]
    assert sorted(records(shared, "manifest-1-of-2.jsonl")) == [1, 3]
    merged = tmp_path / "merged"
    assert cli("batch", "merge", shared / "manifest-0-of-2.jsonl", shared / "manifest-1-of-2.jsonl",
               "--out", merged) == 0
    same_batch(merged, one_process)
    # the first shard alone: items 1 and 3 are said missing (exit 1)
    assert cli("batch", "merge", shared / "manifest-0-of-2.jsonl", "--out", tmp_path / "half") == 1

    from shapemove.core.batch.merge import merge_manifests

    other = tmp_path / "other"            # the same items with another setting: refused
    assert cli("generate", "--prompts", prompts, "--out", other, "--shard", "1/2", *FAST, "--temperature", "0.5") == 0
    with pytest.raises(ShapeMoveError, match="item 1 differs"):
        merge_manifests([shared / "manifest-1-of-2.jsonl", other / "manifest-1-of-2.jsonl"], tmp_path / "m2")
    forged = tmp_path / "forged"          # same key, other bytes: refused
    forged.mkdir()
    rec = records(shared, "manifest-1-of-2.jsonl")[1]
    (forged / rec["outputs"][0]["file"]).write_bytes(b"x")
    rec["outputs"][0].update(bytes=1, sha256=hashlib.sha256(b"x").hexdigest())
    (forged / "manifest.jsonl").write_text(json.dumps(rec) + "\n")
    with pytest.raises(ShapeMoveError, match="item 1 has other files"):
        merge_manifests([shared / "manifest-1-of-2.jsonl", forged / "manifest.jsonl"], tmp_path / "m3")


@pytest.mark.slow
def test_a_local_dask_cluster_gives_the_same_manifest_as_two_processes(prompts, tmp_path, two_processes):
    """A 2-worker Dask cluster started here on loopback: the same manifest as --jobs 2, item for
    item (all but the timing), and the same files byte for byte."""
    need_module("distributed", "the Dask engine needs distributed (pip install distributed)")
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, worker_dashboard_address=None) as cluster:
        out = tmp_path / "dask"
        assert cli("generate", "--prompts", prompts, "--out", out, "--dask", cluster.scheduler_address, *FAST) == 0
        workers = {r["timing"]["worker"] for r in records(out).values()}
    same_batch(out, two_processes)
    assert len(workers) == 2


def test_batch_options_are_refused_with_a_sentence(prompts, tmp_path, capsys):
    for argv, said in ((["--shard", "2/2"], "--shard 2/2"), (["--jobs", "0"], "--jobs"),
                       (["--prompt", "a person waves"], "not both"), (["--jobs", "2", "--dask", "tcp://x:1"], "not both")):
        assert cli("generate", "--prompts", prompts, "--out", tmp_path / "x", *argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and said in err[0], err
    assert cli("generate", "--prompts", prompts, "--out", tmp_path / "x.npz") == 2


def test_progress_lines_say_done_failed_left_rate_and_time_left():
    import io

    from shapemove.core.batch.progress import BatchProgress

    out = io.StringIO()
    p = BatchProgress(10, already=2, label="generate", stream=out, interval=0.0, bar=False)
    p.t0 -= 4.0                      # 4 s into the run
    p.update(True)
    p.update(False)
    p.update(True)
    p.close()
    lines = out.getvalue().splitlines()
    assert lines[-1].startswith("generate: 4 of 10 done (2 before this run), 1 failed, 5 left, 0.7")
    assert lines[-1].endswith("items/s, about 7s left")        # 5 left at 3 items / 4 s
    assert len(lines) == 3                                     # one line per update, none repeated at the end


def test_a_batch_worker_and_the_extension_worker_share_one_loaded_model(tmp_path):
    """generate_item.generator_for hands out loaded_generator's model (one cache per process), with
    the batch's retrieval setting; a changed manifest.json loads the model folder again."""
    import shutil

    from shapemove.core.batch.generate_item import generator_for
    from shapemove.core.generation.loaded_generator import loaded_generator

    model = tmp_path / "model"
    shutil.copytree(ROOT / "weights" / "default", model)
    gen = loaded_generator(model)
    batch = generator_for({"model": str(model), "body_model": None, "library": None}, retrieval=False,
                          captured=False)
    assert batch is gen and gen.t5.memory_enabled is False and gen.captured_on is False   # --no-library
    assert loaded_generator(model) is gen and gen.t5.memory_enabled is True   # a hand-out turns retrieval on again
    assert gen.captured_on is True
    from shapemove.core.batch.generate_item import motion_facts
    from shapemove.core.scene.motion_file import Motion

    import numpy as np

    m = Motion(joints=np.zeros((2, 22, 3), np.float32), betas=np.zeros(10, np.float32),
               poses=np.zeros((2, 24, 3), np.float32), transl=np.zeros((2, 3), np.float32), fps=20.0,
               body_model="openbody")
    m.provenance = "captured: HDM05 bd kickLFront 003 (CC BY-SA 3.0)"
    assert motion_facts(m)["source"]["kind"] == "captured"   # a built-in library take, no notes
    m.provenance = "generated"
    assert motion_facts(m)["source"]["kind"] == "generated"
    st = (model / "manifest.json").stat()
    os.utime(model / "manifest.json", ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    assert loaded_generator(model) is not gen                           # the folder changed: loaded again


def test_workers_fork_from_a_warm_process_only_without_blender(monkeypatch):
    """``generate --prompts --jobs N`` loads the model once here and forks the workers from it;
    ``render`` (no preload: bpy) and a process that imported bpy spawn them."""
    from shapemove.core.batch.engines import start_method

    monkeypatch.delitem(sys.modules, "bpy", raising=False)
    assert start_method(None) == "spawn" and start_method(print) == "fork"
    monkeypatch.setitem(sys.modules, "bpy", object())
    assert start_method(print) == "spawn"
