"""How the action signatures (``core/eval/action_signatures.py``) read real captured clips: for each
signed action, the share of the built data's real clips of it that pass, and the share of every
other action's real clips that pass (``core/eval/signature_accuracy.py`` says how clips are read).

    python tools/signature_check.py --data data/built [--split train] [--seconds 3] [--json OUT]
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from shapemove.core.eval.action_signatures import SIGNED
from shapemove.core.eval.signature_accuracy import false_share, own_share, signature_table


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, required=True)
    ap.add_argument("--split", default="train")
    ap.add_argument("--seconds", type=float, default=None, help="read each clip as a window this long")
    ap.add_argument("--json", type=Path, default=None)
    a = ap.parse_args()
    table = signature_table(a.data, a.split, a.seconds)
    own, false = own_share(table), false_share(table)
    for k in SIGNED:
        most = max(((x, table[x][k]) for x in table if x != k), key=lambda t: t[1], default=("-", 0.0))
        print(f"{k:14s} own clips pass {100 * own.get(k, 0.0):5.1f}% of {table.get(k, {}).get('n', 0):3d}; "
              f"other clips {100 * false[k]:4.1f}% (most: {most[0]} {100 * most[1]:.0f}%)")
    if a.json:
        a.json.write_text(json.dumps({"own": own, "false": false, "table": table}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
