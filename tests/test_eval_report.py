"""tools/eval_report.py writes the evaluation tables between the markers of docs/evaluation.md."""
import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("eval_report", ROOT / "tools" / "eval_report.py")
eval_report = importlib.util.module_from_spec(spec)
spec.loader.exec_module(eval_report)

RECON = {"mpjpe_mm": 358.104, "mpjpe_local_mm": 45.67, "bone_err_mm": 5.0011, "penetrate_cm": 4.1454,
         "float_cm": 2.656, "skate_pct": 31.973, "dyn_stable_pct": 50.92, "code_usage_pct": 38.0, "clips": 40,
         "ground_truth": {"mpjpe_mm": 0.0, "mpjpe_local_mm": 0.0, "bone_err_mm": 3.6e-05, "penetrate_cm": 3.489,
                          "float_cm": 3.9465, "skate_pct": 29.95, "dyn_stable_pct": 50.38, "code_usage_pct": None}}


def test_tables_replace_the_marked_blocks(tmp_path):
    import json

    readme = tmp_path / "evaluation.md"
    readme.write_text("intro\n<!-- eval:recon -->\nold table\n<!-- /eval:recon -->\n"
                      "<!-- eval:generate -->\nold\n<!-- /eval:generate -->\nend\n")
    (tmp_path / "r.json").write_text(json.dumps(RECON))
    args = ["--recon", str(tmp_path / "r.json"), "--untrained", str(tmp_path / "none.json"),
            "--generate", str(tmp_path / "none.json"), "--page", str(readme)]
    assert eval_report.main(args) == 0
    text = readme.read_text()
    assert "old table" not in text and text.startswith("intro\n") and text.endswith("end\n")
    assert "| MPJPE, root-aligned (mm) | 45.7 | 0.0 | — |" in text
    assert "| bone-length error (mm) | 5.0 | 0.0 | 45.9 |" in text
    assert "| codebook usage (%) | 38.0 | — | — |" in text
    assert "<!-- eval:generate -->\nold\n" in text  # no generate JSON: that block stays
    assert eval_report.main(args) == 0 and readme.read_text() == text  # idempotent


def test_missing_markers_are_a_clear_error(tmp_path):
    with pytest.raises(SystemExit, match="no <!-- eval:recon -->"):
        eval_report.replace_block("no markers here", "recon", "x")


def test_the_default_page_is_the_manuals_and_holds_every_block():
    """`make eval` writes docs/evaluation.md (not the README), which has every marked table."""
    page = ROOT / "docs" / "evaluation.md"
    text = page.read_text(encoding="utf-8")
    for name in ("recon", "generate", "shape", "paraphrase"):
        assert f"<!-- eval:{name} -->\n" in text and f"\n<!-- /eval:{name} -->" in text, name
    assert "<!-- eval:" not in (ROOT / "README.md").read_text(encoding="utf-8")
    src = (ROOT / "tools" / "eval_report.py").read_text()
    assert 'default=ROOT / "docs" / "evaluation.md"' in src
