"""eval paraphrase: held-out prompts -> generated motion -> TMA action, per action and overall."""
import json

import pytest

from shapemove.core.errors import ShapeMoveError
from tiny_models import tiny_bundle  # noqa: F401  (session fixture)


def test_paraphrase_eval_on_a_tiny_model(tiny_bundle, tmp_path, capsys):  # noqa: F811
    from shapemove.cli import main

    model, _ = tiny_bundle
    prompts = {"prompts": [{"text": "Someone strolls down the street.", "action": "walk"},
                           {"text": "A footballer boots the ball away.", "action": "kick", "also": ["kick ball"]},
                           {"text": "The kid dashes to the bus.", "action": "run", "also": ["sprint", "walk"]},
                           {"text": "A person does a handstand on the beach.", "action": "handstand"}]}
    (tmp_path / "p.json").write_text(json.dumps(prompts))
    assert main(["eval", "paraphrase", "--model", str(model), "--prompts", str(tmp_path / "p.json"), "--seconds", "1",
                 "--json", str(tmp_path / "r.json"), "--quiet"]) == 0
    out = capsys.readouterr().out
    res = json.loads((tmp_path / "r.json").read_text())
    known = res["actions"]
    expected_known = [p for p in prompts["prompts"] if p["action"] in known]
    assert "handstand" in res["unknown_action"] and res["unknown_prompts"] == len(prompts["prompts"]) - len(expected_known)
    rows = res["rows"]
    assert [r["text"] for r in rows] == [p["text"] for p in expected_known]
    for kind in ("motion", "text"):
        strict = sum(r[f"{kind}_pred"] == r["action"] for r in rows)
        lenient = sum(r[f"{kind}_pred"] == r["action"] or r[f"{kind}_pred"] in r["also"] for r in rows)
        assert res[kind]["accuracy"] == pytest.approx(strict / len(rows))
        assert res[kind]["accuracy_lenient"] == pytest.approx(lenient / len(rows))
        assert all(r[f"{kind}_pred"] in known for r in rows)
    assert "overall" in out and "Held-out paraphrases" in out


def test_bad_prompt_files(tmp_path):
    from shapemove.core.eval.paraphrase_eval import load_prompts

    assert len(load_prompts()) >= 100  # the shipped held-out set
    (tmp_path / "a.json").write_text('{"prompts": [{"text": 3}]}')
    with pytest.raises(ShapeMoveError, match="prompt 0 must be"):
        load_prompts(tmp_path / "a.json")
    (tmp_path / "b.json").write_text("not json")
    with pytest.raises(ShapeMoveError, match="not valid JSON"):
        load_prompts(tmp_path / "b.json")
    with pytest.raises(ShapeMoveError, match="not found"):
        load_prompts(tmp_path / "missing.json")
