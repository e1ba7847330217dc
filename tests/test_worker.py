"""The job worker: protocol, real `python -m shapemove worker` subprocesses, cancel, death and
restart, the in-process runner, and the bpy-side poller (real bpy)."""
from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from conftest import need_module
from synthetic_smpl import write_model

from shapemove.core.errors import ShapeMoveError
from shapemove.core.worker import protocol as P
from shapemove.core.worker.client import InProcessRunner, WorkerClient, resolve_python

PY = sys.executable  # the test venv's Python (has torch and shapemove)
CMD = [PY, "-m", "shapemove", "worker"]
# Short real Bandai clips (65-82 frames at 30 fps: 2.2-2.7 s), so a build step takes a second or so
CLIPS = [f"dataset-2_raise-up-both-hands_{c}" for c in
         ("exhausted_006", "feminine_007", "feminine_011", "masculine_012", "youthful_007", "youthful_039")]


@pytest.fixture
def client():
    """A worker of its own (for tests that kill or stop it)."""
    c = WorkerClient(PY, command=CMD)
    yield c
    c.stop()


@pytest.fixture(scope="module")
def shared():
    """One worker for the tests that leave it serving (saves a torch import per test)."""
    c = WorkerClient(PY, command=CMD)
    yield c
    c.stop()


def wait_for(runner, pred, timeout=60.0) -> list[dict]:
    """Poll until pred(all messages so far) is true; returns the messages."""
    seen: list[dict] = []
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        seen += runner.poll()
        if pred(seen):
            return seen
        time.sleep(0.02)
    raise AssertionError(f"timed out; messages: {seen}")


def ended(jid):
    return lambda msgs: any(m["id"] == jid and m["type"] in ("result", "error") for m in msgs)


def final(msgs, jid) -> dict:
    (m,) = [m for m in msgs if m["id"] == jid and m["type"] in ("result", "error")]
    return m


class RawWorker:
    """The worker process with its stdout read line by line, unparsed (to check what it writes)."""

    def __init__(self):
        self.proc = subprocess.Popen(CMD, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.lines: queue.Queue = queue.Queue()
        threading.Thread(target=lambda: [self.lines.put(x) for x in self.proc.stdout], daemon=True).start()
        threading.Thread(target=self.proc.stderr.read, daemon=True).start()

    def send(self, raw: bytes) -> None:
        self.proc.stdin.write(raw)
        self.proc.stdin.flush()

    def read_until(self, rid, timeout=60.0) -> list[bytes]:
        out = []
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            try:
                line = self.lines.get(timeout=0.1)
            except queue.Empty:
                continue
            out.append(line)
            msg = json.loads(line)
            if msg["id"] == rid and msg["type"] in ("result", "error"):
                return out
        raise AssertionError(f"no answer to {rid}: {out}")

    def close(self):
        self.proc.kill()
        self.proc.wait()


# -- protocol ----------------------------------------------------------------------------------
def test_protocol_round_trip_and_validation():
    req = P.decode_request(P.encode_request("j1", "measure", {"betas": [0.5] * 10}))
    assert (req.id, req.op, req.params) == ("j1", "measure", {"betas": [0.5] * 10})
    assert P.decode_request(b'{"id": 7, "op": "ping"}\n') == P.Request(7, "ping", {})
    # numpy values travel as plain JSON, exactly
    x = np.array([0.1, 1 / 3], np.float64)
    msg = P.decode_response(P.encode_response(P.result("j1", {"x": x, "n": np.int64(3)})))
    assert msg["result"] == {"x": [0.1, 1 / 3], "n": 3} and msg["cancelled"] is False
    for line, words in [("", "empty"), ("{oops", "not valid JSON"), ("[1]", "JSON object"),
                        ('{"op": "ping"}', '"id"'), ('{"id": true, "op": "ping"}', '"id"'),
                        ('{"id": "a"}', '"op"'), ('{"id": "a", "op": "x", "params": [1]}', "params"),
                        ('{"id": "a", "op": "x", "extra": 1}', "unknown keys: extra")]:
        with pytest.raises(P.ProtocolError, match=words):
            P.decode_request(line)
    with pytest.raises(P.ProtocolError) as info:
        P.decode_request('{"id": "a9", "op": 3}')
    assert info.value.request_id == "a9"  # the error can still name the request
    for bad in [P.progress("a", 1.5), P.progress("a", float("nan")), {"id": "a", "type": "done"},
                {"id": "a", "type": "result", "result": [1]}, {"id": "a", "type": "log"}]:
        with pytest.raises(P.ProtocolError):
            P.encode_response(bad)
    with pytest.raises(P.ProtocolError, match="JSON"):
        P.encode_response(P.result("a", {"obj": object()}))


def test_resolve_python(tmp_path):
    assert resolve_python(PY) == __import__("pathlib").Path(PY)
    venv = tmp_path / "venv" / "bin"
    venv.mkdir(parents=True)
    (venv / "python").write_text("")
    assert resolve_python(tmp_path / "venv") == venv / "python"
    with pytest.raises(ShapeMoveError, match="not found"):
        resolve_python(tmp_path / "nope")
    with pytest.raises(ShapeMoveError, match="no Python executable"):
        resolve_python(tmp_path)


# -- the worker process ------------------------------------------------------------------------
def test_ping_round_trip(shared):
    res = shared.call("ping", timeout=30)
    assert res["pong"] is True and res["pid"] == shared.pid != os.getpid()
    assert res["protocol"] == P.PROTOCOL_VERSION
    assert {"body_info", "measure", "build_dataset", "train_vae"} <= set(res["ops"])
    assert {"generate", "retarget", "search", "train"} <= set(res["ops"])  # the panel ops (jobs_shapemove)
    assert shared.alive() and not shared.pending


def test_body_info_real_facts(shared, tmp_path):
    from shapemove.core.body.openbody_asset import DEFAULT_PATH

    if DEFAULT_PATH.is_file():
        with np.load(DEFAULT_PATH) as npz:
            v, f = npz["v_template"], npz["faces"]
        info = shared.call("body_info", timeout=60)
        assert info["name"] == "openbody-v1" and info["num_vertices"] == len(v) and info["num_faces"] == len(f)
        assert info["height_m"] == pytest.approx(float(v[:, 1].max() - v[:, 1].min()), abs=1e-5)
        assert len(info["phenotype_names"]) == 6
    arrays = write_model(tmp_path / "SMPL_NEUTRAL.npz", "smpl")
    info = shared.call("body_info", {"body": str(tmp_path / "SMPL_NEUTRAL.npz")}, timeout=60)
    vt = arrays["v_template"]
    assert info["num_vertices"] == len(vt) and info["num_faces"] == len(arrays["f"])
    assert info["num_joints"] == 24 and info["num_betas"] == 10 and info["joint_names"][0] == "pelvis"
    assert info["height_m"] == pytest.approx(float(vt[:, 1].max() - vt[:, 1].min()), abs=1e-5)


def _openbody_lengths_cm(betas) -> dict:
    """Height and arm length (cm) of OpenBody with ``betas``, straight from the asset's arrays in
    numpy: the linear shape space, the joint regressor, the joint path shoulder-elbow-wrist."""
    from shapemove.core.body.openbody_asset import DEFAULT_PATH
    from shapemove.core.body.skeleton import JOINT_INDEX as JI

    with np.load(DEFAULT_PATH) as z:
        v = z["v_template"].astype(np.float64) + z["shapedirs"].astype(np.float64) @ np.asarray(betas, np.float64)
        j = z["j_regressor"].astype(np.float64) @ v
    arm = np.mean([np.linalg.norm(j[JI[f"{s}_shoulder"]] - j[JI[f"{s}_elbow"]])
                   + np.linalg.norm(j[JI[f"{s}_elbow"]] - j[JI[f"{s}_wrist"]]) for s in ("left", "right")])
    return {"height_cm": 100 * (v[:, 1].max() - v[:, 1].min()), "arm_length_cm": 100 * arm}


def test_measure_op_reports_the_bodys_own_lengths(shared):
    betas = [1.5, -0.5, 0, 0, 0.3, 0, 0, 0, 0, -1.0]
    got = shared.call("measure", {"betas": betas}, timeout=90)
    want = _openbody_lengths_cm(betas)
    assert set(got) == {"height_cm", "chest_cm", "waist_cm", "hip_cm", "arm_length_cm", "leg_length_cm", "mass_kg", "bmi"}
    assert got["bmi"] == pytest.approx(got["mass_kg"] / (got["height_cm"] / 100) ** 2, rel=1e-5)
    for k, v in want.items():  # float32 in the worker: 0.01 mm
        assert got[k] == pytest.approx(v, abs=1e-3)
    # the betas reached the body: the mean shape is measurably different
    assert abs(shared.call("measure", {}, timeout=90)["height_cm"] - got["height_cm"]) > 0.5
    assert 40 < got["waist_cm"] < got["chest_cm"] < 200


def test_errors_unknown_op_and_bad_input(shared):
    j1 = shared.submit("teleport", {})
    j2 = shared.submit("body_info", {"body": "/no/such/model.npz"})
    j3 = shared.submit("measure", {"betas": [1, 2, 3]})
    j4 = shared.submit("build_dataset", {"out": "/tmp/x"})
    msgs = wait_for(shared, lambda m: all(ended(j)(m) for j in (j1, j2, j3, j4)), timeout=90)
    e1 = final(msgs, j1)
    assert e1["type"] == "error" and "unknown op 'teleport'" in e1["message"]
    assert all(op in e1["message"] for op in ("body_info", "train_vae", "ping", "cancel"))
    e2 = final(msgs, j2)
    assert e2["error_type"] == "ShapeMoveError" and "/no/such/model.npz" in e2["message"]
    e3 = final(msgs, j3)
    assert e3["error_type"] == "ShapeMoveError" and "betas must be" in e3["message"]
    e4 = final(msgs, j4)
    assert e4["message"] == "op 'build_dataset': missing parameter 'sources'"
    with pytest.raises(ShapeMoveError, match="'betas' must be a list of numbers"):
        shared.call("measure", {"betas": ["tall"] * 10})
    assert shared.call("ping")["pong"]  # still serving


def test_malformed_lines_get_errors_and_worker_keeps_serving():
    w = RawWorker()
    try:
        w.send(b"this is not json\n\xff\xfe{\n[1, 2]\n")
        w.send(b'{"id": "m1", "params": {}}\n{"id": "p1", "op": "ping"}\n')
        lines = w.read_until("p1", timeout=30)
        msgs = [json.loads(x) for x in lines]
        errors = [m for m in msgs if m["type"] == "error"]
        assert len(errors) == 4 and all(m["error_type"] == "ProtocolError" for m in errors)
        assert "not valid JSON" in errors[0]["message"] and errors[0]["id"] is None
        assert "JSON object" in errors[2]["message"]
        assert errors[3]["id"] == "m1" and '"op"' in errors[3]["message"]
        assert msgs[-1]["result"]["pong"] is True
        assert w.proc.poll() is None
    finally:
        w.close()


def test_stdout_has_only_protocol_lines_when_a_job_prints():
    """`cli` runs a command in the worker: argparse prints its help with print() - that text must
    come out as log messages, never as raw stdout."""
    w = RawWorker()
    try:
        w.send(b'{"id": "h", "op": "cli", "params": {"argv": ["data", "build", "--help"]}}\n')
        w.send(b'{"id": "bad", "op": "cli", "params": {"argv": ["data", "build", "--nonsense"]}}\n')
        lines = w.read_until("h") + w.read_until("bad")
        msgs = [json.loads(x) for x in lines]  # every line parses
        assert all(x.endswith(b"\n") and x.count(b"\n") == 1 for x in lines)
        logs = "\n".join(m["message"] for m in msgs if m["type"] == "log" and m["id"] == "h")
        assert "--source" in logs and "usage:" in logs
        assert final(msgs, "h") == P.result("h", {"exit_code": 0})
        err = final(msgs, "bad")
        assert err["type"] == "error" and "exit code 2" in err["message"] and "--nonsense" in err["message"]
    finally:
        w.close()


def test_queued_job_cancels_at_once(shared):
    j1 = shared.submit("measure", {"betas": [0.4321] * 10})   # a body measured nowhere else (measure keeps bodies)
    j2 = shared.submit("body_info", {})
    assert shared.cancel(j2)
    msgs = wait_for(shared, ended(j1), timeout=90)
    order = [m["id"] for m in msgs if m["type"] in ("result", "error")]
    assert order == [j2, j1]  # j2 left the queue before j1 finished
    assert final(msgs, j2) == P.result(j2, {}, cancelled=True)
    assert final(msgs, j1)["cancelled"] is False and final(msgs, j1)["result"]["height_cm"] > 100


def build_params(mocap_root, out, clips):
    return {"sources": [str(mocap_root / "bandai")], "out": str(out), "only": clips, "augment_share": 0.0}


def wait_running(client, jid, timeout=60.0) -> None:
    """Until the worker says ``jid`` is its running job (ping is answered while a job runs)."""
    end = time.monotonic() + timeout
    while client.call("ping")["running"] != jid:
        assert time.monotonic() < end
        time.sleep(0.05)


def test_build_dataset_streams_progress_and_cancels(shared, mocap_root, tmp_path):
    jid = shared.submit("build_dataset", build_params(mocap_root, tmp_path / "ds", CLIPS))
    msgs = wait_for(shared, lambda m: any(x["type"] == "progress" for x in m), timeout=120)
    assert shared.cancel(jid)
    msgs += wait_for(shared, ended(jid), timeout=60)
    res = final(msgs, jid)
    assert res["type"] == "result" and res["cancelled"] is True
    r = res["result"]
    done = r["built"] + r["skipped_done"] + len(r["failures"])
    assert 1 <= done < len(CLIPS)  # stopped after the clip in progress
    fractions = [m["fraction"] for m in msgs if m["type"] == "progress"]
    assert fractions == [pytest.approx(k / len(CLIPS)) for k in range(1, done + 1)]
    assert [m["message"] for m in msgs if m["type"] == "progress"][0] in CLIPS
    assert (tmp_path / "ds" / "build_report.txt").read_text().startswith("clips built: ")
    assert shared.call("ping")["running"] is None


def test_killed_worker_is_reported_and_restarted(client, mocap_root, tmp_path):
    jid = client.submit("build_dataset", build_params(mocap_root, tmp_path / "ds", CLIPS))
    queued = client.submit("body_info", {})
    wait_running(client, jid)
    old_pid = client.pid
    os.kill(old_pid, signal.SIGKILL)
    msgs = wait_for(client, lambda m: ended(jid)(m) and ended(queued)(m), timeout=30)
    for j in (jid, queued):
        err = final(msgs, j)
        assert err["type"] == "error" and err["message"].startswith("worker process died (exit code -9)")
    assert not client.alive() and client.exit_code == -9 and not client.pending
    assert client.poll() == []  # nothing more for those jobs
    res = client.call("ping", timeout=30)  # submit starts a fresh worker
    assert client.alive() and res["pid"] == client.pid != old_pid and client.starts == 2


def test_stop_ends_running_job_once(client, mocap_root, tmp_path):
    jid = client.submit("build_dataset", build_params(mocap_root, tmp_path / "ds", CLIPS))
    wait_running(client, jid)
    client.stop(timeout=60)
    msgs = wait_for(client, ended(jid), timeout=5)
    assert [m["type"] for m in msgs if m["id"] == jid and m["type"] in ("result", "error")] == ["result"]
    assert final(msgs, jid)["cancelled"] is True  # shutdown cancels; the job ended cleanly
    assert not client.alive() and client.exit_code == 0


def test_default_launcher_runs_this_package():
    """Without `command`, the client imports this package's folder as `shapemove` (as in Blender)."""
    c = WorkerClient(PY)
    try:
        assert "-c" in c.command and c.call("ping", timeout=30)["pong"]
        assert c.call("env_info", timeout=60)["executable"] == PY
    finally:
        c.stop()


def test_python_without_requirements_says_what_is_missing():
    """A Python without numpy/torch (e.g. a wrong preference): the worker starts, jobs say why they fail."""
    bare = next((p for p in ("/usr/bin/python3", "/usr/local/bin/python3") if os.path.isfile(p) and subprocess.run(
        [p, "-c", "import numpy"], capture_output=True).returncode), None)
    if bare is None:
        pytest.skip("no Python without numpy on this machine")
    c = WorkerClient(bare)
    try:
        assert c.call("ping", timeout=30)["pong"]
        with pytest.raises(ShapeMoveError, match=f"needs the Python package 'numpy', which is not installed in {bare}"):
            c.call("body_info", timeout=30)
        with pytest.raises(ShapeMoveError, match="unknown op 'generate'.*panel ops .* need the Python package"):
            c.call("generate", {}, timeout=30)
    finally:
        c.stop()


# -- in-process --------------------------------------------------------------------------------
def test_in_process_runner_matches_worker(shared):
    r = InProcessRunner()
    try:
        a = r.call("measure", {"betas": [0.5] + [0.0] * 9}, timeout=90)
        want = _openbody_lengths_cm([0.5] + [0.0] * 9)
        assert all(a[k] == pytest.approx(v, abs=1e-3) for k, v in want.items())
        assert r.call("ping")["pid"] == os.getpid()
        with pytest.raises(ShapeMoveError, match="unknown op 'nope'"):
            r.call("nope")
        # the `cli` op belongs to the worker process (cli/worker.py adds it), not to Blender's runner
        with pytest.raises(ShapeMoveError, match="unknown op 'cli'"):
            r.call("cli", {})
    finally:
        r.stop()
    assert not r.alive()


@pytest.mark.slow
def test_train_vae_streams_progress_and_cancels(shared, tiny_dataset, tmp_path):
    cfg = {"base": "small", "width": 32, "shape_hidden": 32, "depth": 1,
           "train": {"steps": 400, "batch_size": 4, "window": 16, "log_every": 1, "val_every": 10_000,
                     "ckpt_every": 10_000, "warmup_steps": 1}}
    jid = shared.submit("train_vae", {"data": str(tiny_dataset), "out": str(tmp_path / "run"), "config": cfg})
    msgs = wait_for(shared, lambda m: sum(x["type"] == "progress" for x in m) >= 3, timeout=120)
    steps = [int(m["message"].split()[1].split("/")[0]) for m in msgs if m["type"] == "progress"]
    fractions = [m["fraction"] for m in msgs if m["type"] == "progress"]
    assert steps[0] == 1 and steps == sorted(set(steps)) and fractions == [k / 400 for k in steps]
    shared.cancel(jid)
    msgs = wait_for(shared, ended(jid), timeout=60)
    res = final(msgs, jid)
    assert res["type"] == "result" and res["cancelled"] is True
    assert 3 <= res["result"]["metrics"]["step"] < 400
    assert (tmp_path / "run" / "last.pt").is_file() and not (tmp_path / "run" / "savae.pt").exists()


# -- bpy side ----------------------------------------------------------------------------------
def test_bpy_poller_dispatches_to_callbacks(monkeypatch):
    need_module("bpy")
    import bpy

    from shapemove.shapemove_addon import jobs

    jobs.register()
    mgr = jobs.JobManager(WorkerClient(PY))
    try:
        got, errors, progress = [], [], []
        j1 = mgr.submit("ping", label="Ping", on_result=got.append)
        j2 = mgr.submit("teleport", on_error=errors.append)
        assert bpy.app.timers.is_registered(jobs._tick) and mgr.busy
        end = time.monotonic() + 30
        while mgr.poll() is not None:  # what the timer does on every tick
            assert time.monotonic() < end
            time.sleep(0.02)
        assert [m["id"] for m in got] == [j1] and got[0]["result"]["pong"] is True
        assert got[0]["result"]["pid"] == mgr.runner.pid != os.getpid()
        assert [m["id"] for m in errors] == [j2] and "unknown op 'teleport'" in errors[0]["message"]
        assert bpy.context.window_manager.shapemove_status.startswith("teleport failed: unknown op")
        mgr.submit("ping", label="Ping", on_result=lambda m: 1 / 0)  # a broken callback must not stop polling
        end = time.monotonic() + 30
        while mgr.poll() is not None:
            assert time.monotonic() < end
            time.sleep(0.02)
        assert "ZeroDivisionError" in mgr.status and not mgr.busy
        # the add-on's singleton picks the worker from $SHAPEMOVE_PYTHON when no preference is set
        monkeypatch.setenv(jobs.PYTHON_ENV_VAR, PY)
        assert jobs.python_setting() == PY
        single = jobs.manager()
        jid = single.submit("ping", on_progress=progress.append)
        assert isinstance(single.runner, WorkerClient) and jid in single.jobs
        end = time.monotonic() + 30
        while jobs._tick() is not None:
            assert time.monotonic() < end
            time.sleep(0.02)
        assert bpy.context.window_manager.shapemove_status == "ping: done"
    finally:
        mgr.set_runner(None)
        jobs.unregister()
    assert not bpy.app.timers.is_registered(jobs._tick) and not hasattr(bpy.types.WindowManager, "shapemove_status")
