"""Lost work (issue 11): `train vae|t5|tma` into a folder holding a finished model or an
interrupted run is refused without --resume/--force; a resumed run's log.jsonl has each step once."""
import json

import pytest

from shapemove.cli import main
from shapemove.core.errors import ShapeMoveError
from shapemove.core.train.run_guard import check_run_folder
from shapemove.core.train.run_log import record


@pytest.mark.parametrize("kind, finished", [("vae", "savae.pt"), ("t5", "t5/shapemove.json"), ("tma", "tma.pt")])
def test_finished_model_is_not_replaced(tmp_path, kind, finished, capsys):
    run = tmp_path / "run"
    (run / finished).parent.mkdir(parents=True, exist_ok=True)
    (run / finished).write_bytes(b"model")
    with pytest.raises(ShapeMoveError, match=f"already holds a finished {kind} model.*--resume.*--force"):
        check_run_folder(run, kind)
    check_run_folder(run, kind, resume=True)
    check_run_folder(run, kind, force=True)
    # through the command line: a sentence, exit 2, the model untouched
    extra = ["--vae", str(tmp_path / "v.pt")] if kind == "t5" else []
    code = main(["train", kind, "--data", str(tmp_path / "data"), "--out", str(run), *extra])
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "already holds a finished" in err and "Traceback" not in err
    assert (run / finished).read_bytes() == b"model"


def test_interrupted_run_and_bad_out(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    check_run_folder(run, "vae")  # empty folder: fine
    (run / "last.pt").write_bytes(b"x")
    with pytest.raises(ShapeMoveError, match="interrupted run"):
        check_run_folder(run, "tma")
    (tmp_path / "file").write_text("x")
    with pytest.raises(ShapeMoveError, match="is a file, not a folder"):
        check_run_folder(tmp_path / "file", "vae", force=True)


def test_resumed_log_has_each_step_once(tmp_path):
    for s in (10, 20, 30, 40):
        record(tmp_path, {"step": s, "run": 1}, None, s, 100, "")
    with open(tmp_path / "log.jsonl", "a") as fh:
        fh.write('{"step": 50, "ru')  # killed mid-write
    # resumed from the checkpoint at step 20: steps 30.. are logged again
    for s in (30, 40, 50, 60):
        record(tmp_path, {"step": s, "run": 2}, None, s, 100, "")
    lines = [json.loads(x) for x in (tmp_path / "log.jsonl").read_text().splitlines()]
    assert [x["step"] for x in lines] == [10, 20, 30, 40, 50, 60]
    assert [x["run"] for x in lines] == [1, 1, 2, 2, 2, 2]
