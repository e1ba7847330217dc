"""How long `generate --explain` takes to make the plan of each prompt of the held-out sets, in a
warm process (modules loaded, the caption verb table read once), the reading cache emptied before
each prompt so that every prompt is read from its words:

    .venv/bin/python tools/explain_timing.py
"""
from __future__ import annotations

import json
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SETS = ("heldout_paraphrases", "heldout_paraphrases_blind", "heldout_sequences", "heldout_sides",
        "heldout_two_things", "heldout_pace_blind")


def prompts() -> list[str]:
    out = []
    for name in SETS:
        data = json.loads((ROOT / "configs" / f"{name}.json").read_text())
        for row in data.get("prompts", data.get("rows", [])) + data.get("compositions", []):
            out.append(row if isinstance(row, str) else row[0] if isinstance(row, list) else row["text"])
    return out


def main() -> int:
    from shapemove.core.plan.explain import plan_json
    from shapemove.core.plan.words import read_words

    texts = prompts()
    plan_json(texts[0], 4)   # warm: modules and tables loaded
    times = []
    for t in texts:
        read_words.cache_clear()
        start = time.perf_counter()
        plan_json(t, 4)
        times.append((time.perf_counter() - start) * 1000)
    times.sort()
    print(f"{len(texts)} held-out prompts: median {times[len(times) // 2]:.1f} ms, "
          f"95th percentile {times[int(len(times) * 0.95)]:.1f} ms, max {times[-1]:.1f} ms per plan")
    return 0 if times[-1] < 50 else 1


if __name__ == "__main__":
    raise SystemExit(main())
