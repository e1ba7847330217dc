"""Fit OpenBody's betas -> (chest, waist, hip) girth regression on mesh measurements and write
``assets/girth_regression.npz`` (used by ``core/body/shape_from_measurements.py`` so that a shape
text with numbers is fitted in milliseconds). Rerun after OpenBody changes (the file records the
body's key; a stale file is ignored and the slow mesh fit is used).

    python tools/build_girth_regression.py [--samples 400] [--body openbody]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT.parent))


def main() -> int:
    from shapemove.core.body.load import load_body_model
    from shapemove.core.body.shape_from_measurements import REGRESSION_FILE, fit_girth_regression

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=400)
    ap.add_argument("--body", default="openbody")
    ap.add_argument("--out", type=Path, default=REGRESSION_FILE)
    args = ap.parse_args()
    reg = fit_girth_regression(load_body_model(args.body), args.samples, progress=True)
    reg.save(args.out)
    print(f"wrote {args.out}: fit rms (cm) chest {reg.rms_cm[0]:.2f}, waist {reg.rms_cm[1]:.2f}, hip {reg.rms_cm[2]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
