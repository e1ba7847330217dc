"""eval paraphrase: held-out prompts -> generated motion -> TMA action, per action and overall."""
import json

import pytest

from shapemove.core.errors import ShapeMoveError
from tiny_models import tiny_bundle  # noqa: F401  (session fixture)


def test_paraphrase_eval_on_a_tiny_model(tiny_bundle, tmp_path, capsys):  # noqa: F811
    from shapemove.cli import main

    model, data = tiny_bundle
    prompts = {"prompts": [{"text": "Someone strolls down the street.", "action": "walk"},
                           {"text": "A footballer boots the ball away.", "action": "kick", "also": ["kick ball"]},
                           {"text": "The kid dashes to the bus.", "action": "run", "also": ["sprint", "walk"]},
                           {"text": "A person does a handstand on the beach.", "action": "handstand"}]}
    (tmp_path / "p.json").write_text(json.dumps(prompts))
    assert main(["eval", "paraphrase", "--model", str(model), "--prompts", str(tmp_path / "p.json"), "--seconds", "1",
                 "--data", str(data), "--json", str(tmp_path / "r.json"), "--quiet"]) == 0
    out = capsys.readouterr().out
    res = json.loads((tmp_path / "r.json").read_text())
    known = res["actions"]
    expected_known = [p for p in prompts["prompts"] if p["action"] in known]
    assert "handstand" in res["unknown_action"] and res["unknown_prompts"] == len(prompts["prompts"]) - len(expected_known)
    rows = res["rows"]
    assert [r["text"] for r in rows] == [p["text"] for p in expected_known]
    # the kNN classifier read every training clip of the dataset whose main action the model knows
    metas = [json.loads(ln) for ln in (data / "meta.jsonl").read_text().splitlines() if ln.strip()]
    train = set((data / "train.txt").read_text().split())
    labelled = [m["labels"]["actions"][0] for m in metas
                if m["id"] in train and (m.get("labels") or {}).get("actions") and m["labels"]["actions"][0] in known]
    clf = res["classifier"]
    assert clf["clips"] == len(labelled) and clf["k"] == 5 and clf["split"] == "train"
    assert clf["actions_without_clips"] == sorted(set(known) - set(labelled))
    assert all(r["motion_pred"] in labelled for r in rows)  # kNN names only actions of training clips
    assert clf["ceiling"]["split"] == "test" and "names real test clips' action" in out
    for kind, pred in (("motion", "motion"), ("text", "text"), ("motion_vs_text_prototypes", "motion_proto")):
        strict = sum(r[f"{pred}_pred"] == r["action"] for r in rows)
        lenient = sum(r[f"{pred}_pred"] == r["action"] or r[f"{pred}_pred"] in r["also"] for r in rows)
        assert res[kind]["accuracy"] == pytest.approx(strict / len(rows))
        assert res[kind]["accuracy_lenient"] == pytest.approx(lenient / len(rows))
        assert all(r[f"{pred}_pred"] in known for r in rows)
    assert "overall" in out and "Held-out paraphrases" in out
    # the no-generation baseline: the nearest training caption's real clip, judged without itself
    assert all(r["nearest_caption_pred"] in labelled for r in rows)
    near = sum(r["nearest_caption_pred"] == r["action"] for r in rows)
    assert res["nearest_caption"]["accuracy"] == pytest.approx(near / len(rows))
    counts = {a: labelled.count(a) for a in set(labelled)}
    assert res["frequent"]["actions"] == sorted({r["action"] for r in rows if counts.get(r["action"], 0) >= 20})
    assert "nearest caption (MiniLM) copied" in out
    # what a perfect generator could score on the frequent actions' prompts, by each judge
    fr = res["frequent"]
    assert set(fr["reachable"]) == set(res["reachable"]) and all(v is None or 0 <= v <= 1 for v in fr["reachable"].values())
    assert (fr["reachable"]["motion"] is None) == (fr["motion"]["prompts"] == 0)
    assert res["seeds"] == [0] and all(r["seed"] == 0 for r in rows)
    assert res["seconds"] == 1 and "length: 1 s each" in out and all(r["seconds"] == 1.0 for r in rows)
    raw_right = sum(r["motion_features_pred"] == r["action"] for r in rows if r["action"] in fr["actions"])
    assert fr["motion_features"]["prompts"] == fr["motion"]["prompts"]          # the frequent actions by the raw judge
    assert fr["motion_features"]["accuracy"] == pytest.approx(raw_right / max(1, fr["motion"]["prompts"]))
    # each action's real windows named right, its pairs merged: read off the windows' confusion by hand
    ind = res["indistinct"]
    assert ind["windows_right"] and set(ind["windows_right"]) == set(ind["confusion"])
    for judge, acc in ind["windows_right"].items():
        pairs = {frozenset(p) for p in ind["pairs"][judge]}
        for a, row in ind["confusion"][judge].items():
            named = sum(n for b, n in row.items() if b == a or frozenset((a, b)) in pairs)
            assert acc[a] == pytest.approx(named / sum(row.values()))

    # the signatures: the kick prompt's row read by the kick's (no other prompt's action has one),
    # tallied beside the TMA judge's reading of the same prompt
    sig = res["signature"]
    assert [r["signature_right"] is not None for r in rows] == [r["action"] == "kick" for r in rows]
    kicks = [r for r in rows if r["action"] == "kick"]
    assert sig["prompts"] == len(kicks) and sig["accuracy"] == pytest.approx(
        sum(r["signature_right"] for r in kicks) / len(kicks))
    assert set(sig["per_action"]) == {"kick"} and "physical signatures" in out

    # two seeds: every prompt generated once per seed, seed 0's generations as in the one-seed run,
    # and the accuracies counted over all the generations
    assert main(["eval", "paraphrase", "--model", str(model), "--prompts", str(tmp_path / "p.json"), "--seconds", "1",
                 "--data", str(data), "--json", str(tmp_path / "r2.json"), "--quiet", "--seed", "0", "3"]) == 0
    two = json.loads((tmp_path / "r2.json").read_text())
    assert two["seeds"] == [0, 3] and [r["seed"] for r in two["rows"]] == [0] * len(rows) + [3] * len(rows)
    assert [r["text"] for r in two["rows"]] == [r["text"] for r in rows] * 2
    keys = ("motion_pred", "motion_features_pred", "text_pred", "nearest_caption_pred", "kept_clips")
    assert [[r[k] for k in keys] for r in two["rows"][:len(rows)]] == [[r[k] for k in keys] for r in rows]
    right = sum(r["motion_pred"] == r["action"] for r in two["rows"])
    assert two["motion"]["prompts"] == 2 * len(rows) and two["motion"]["accuracy"] == pytest.approx(right / (2 * len(rows)))
    assert f"each generated on 2 seeds (0, 3), every column counts {2 * len(rows)} generations" in capsys.readouterr().out
    with pytest.raises(ShapeMoveError, match="distinct seeds"):
        from shapemove.core.eval.paraphrase_eval import eval_paraphrase
        eval_paraphrase(model, tmp_path / "p.json", seed=[1, 1], data=data)

    # a user's library (--library): its clips join the memory; with only retrieved clips competing
    # (--retrieval-first 0) the prompt of a walk keeps the library's one clip, a walk, and those that ask
    # for a kick ("boots the ball away") or a run do not (a clip of another action than the one asked does
    # not compete), and the result counts them
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.scene.motion_file import save_motion

    lib = tmp_path / "library"
    lib.mkdir()
    save_motion(lib / "stroll.npz", Generator(model).generate_batch([Request("Someone strolls down the street.",
                                                                             seconds=3, seed=0)])[0])
    assert main(["eval", "paraphrase", "--model", str(model), "--prompts", str(tmp_path / "p.json"), "--seconds", "1",
                 "--data", str(data), "--json", str(tmp_path / "r3.json"), "--quiet", "--library", str(lib),
                 "--retrieval-first", "0"]) == 0
    three = json.loads((tmp_path / "r3.json").read_text())
    assert three["library"] == str(lib) and three["kept_library"] == 1
    assert [r["kept_clips"] == ["library:stroll"] for r in three["rows"]] == [r["action"] == "walk" for r in rows]

    # --model-length: each motion as long as the model makes it (the product's default), not --seconds
    assert main(["eval", "paraphrase", "--model", str(model), "--prompts", str(tmp_path / "p.json"), "--seconds", "1",
                 "--model-length", "--data", str(data), "--json", str(tmp_path / "r4.json"), "--quiet"]) == 0
    four = json.loads((tmp_path / "r4.json").read_text())
    assert four["seconds"] is None and "length: the model's choice" in capsys.readouterr().out


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


def _para_result(motion, ceiling, text, proto, prompts):
    def col(v):
        return {"accuracy": v, "accuracy_lenient": v + 0.05, "prompts": prompts, "per_action": {}}

    return {"motion": col(motion), "text": col(text), "motion_vs_text_prototypes": col(proto),
            "classifier": {"k": 5, "ceiling": {"accuracy": ceiling, "accuracy_lenient": ceiling, "clips": 467}}}


def test_eval_report_writes_the_paraphrase_table(tmp_path):
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("eval_report", root / "tools" / "eval_report.py")
    rep = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(rep)
    (tmp_path / "p.json").write_text(json.dumps(_para_result(0.612, 0.949, 0.362, 0.092, 141)))
    blind = _para_result(0.55, 0.949, 0.30, 0.08, 188)
    blind["motion"]["accuracy_merged"] = 0.58
    (tmp_path / "b.json").write_text(json.dumps(blind))
    readme = tmp_path / "README.md"
    readme.write_text("x\n<!-- eval:paraphrase -->\nstale table\n<!-- /eval:paraphrase -->\ny\n")
    none = ["--recon", str(tmp_path / "no.json"), "--generate", str(tmp_path / "no.json")]
    args = none + ["--paraphrase", str(tmp_path / "p.json"), "--page", str(readme)]
    assert rep.main(args + ["--paraphrase-blind", str(tmp_path / "missing.json")]) == 0
    text = readme.read_text()
    assert "stale table" not in text and "held-out paraphrases (141 prompts)" in text and "blind" not in text
    rows = {ln.split(" | ")[0].strip("| "): ln.split(" | ")[1:] for ln in text.splitlines() if ln.startswith("| ")}
    strict = "generated motion (5 nearest training clips in TMA motion space), strict"
    assert rows[strict][0].strip(" |") == "61.2 %"
    assert rows["the same classifier on real test clips (ceiling), strict"][0].strip(" |") == "94.9 %"
    assert rows["prompt's TMA text vs action text prototypes, lenient"][0].strip(" |") == "41.2 %"
    assert rows["generated motion vs action text prototypes (older classifier), strict"][0].strip(" |") == "9.2 %"
    assert rep.main(args + ["--paraphrase-blind", str(tmp_path / "b.json")]) == 0
    rows = {ln.split(" | ")[0].strip("| "): ln.split(" | ")[1:] for ln in readme.read_text().splitlines()
            if ln.startswith("| ")}
    assert [c.strip(" |") for c in rows[strict]] == ["61.2 %", "55.0 %"]
    merged = "generated motion, merged (a pair the judge does not tell apart in real windows counts)"
    assert [c.strip(" |") for c in rows[merged]] == ["—", "58.0 %"]   # older results have no merged figure
    plain = tmp_path / "PLAIN.md"
    plain.write_text("no paraphrase block\n")
    assert rep.main(none + ["--paraphrase", str(tmp_path / "p.json"), "--page", str(plain)]) == 0
    assert plain.read_text() == "no paraphrase block\n"
    two = dict(_para_result(0.6, 0.949, 0.3, 0.08, 282), seeds=[0, 1])   # 141 prompts on two seeds
    (tmp_path / "p2.json").write_text(json.dumps(two))
    assert rep.main(none + ["--paraphrase", str(tmp_path / "p2.json"), "--page", str(readme)]) == 0
    assert "held-out paraphrases (141 prompts x 2 seeds)" in readme.read_text()
