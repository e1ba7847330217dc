"""Aggregate per-clip metric dicts and print them as a table beside the ground truth.

Each metric is a mean over some frames of its clip (penetrate over penetrating frames, skate over
adjacent frame pairs, ...), recorded as an ``n_*`` count next to it. ``aggregate`` weights every
clip by that count, so the result is the mean over all those frames of the whole set, exactly as
if the clips were one long motion.
"""
from __future__ import annotations

import math

from ..errors import ShapeMoveError

# metric -> (label, unit, better, count key that weights it)
METRICS = {
    "penetrate_cm": ("Penetrate", "cm", "lower", "n_penetrate"),
    "float_cm": ("Float", "cm", "lower", "n_float"),
    "penetrate_all_cm": ("Penetrate (paper: all frames)", "cm", "lower", "n_frames"),
    "float_all_cm": ("Float (paper: all frames)", "cm", "lower", "n_frames"),
    "skate_joints_pct": ("Skate (GMD: foot joints)", "%", "lower", "n_skate"),
    "skate_pct": ("Skate", "%", "lower", "n_skate"),
    "bone_var_mm": ("Bone length var.", "mm", "lower", "n_frames"),
    "bone_err_mm": ("Bone length err.", "mm", "lower", "n_frames"),
    "dyn_stable_pct": ("Dyn. stability", "%", "higher", "n_stability"),
    "zmp_out_cm": ("ZMP outside BoS", "cm", "lower", "n_zmp_out"),
    "mpjpe_mm": ("MPJPE", "mm", "lower", "n_frames"),
}


def _weight_key(key: str) -> str:
    return METRICS[key][3] if key in METRICS else "n_frames"


def aggregate(clips: list[dict]) -> dict:
    """Per-clip dicts -> one dict: count-weighted means of every metric (NaNs skipped), summed
    ``n_*`` counts, "clips" (number of dicts) and "frames" (total frames)."""
    if not clips:
        raise ShapeMoveError("aggregate needs at least one clip")
    keys = [k for k in dict.fromkeys(k for c in clips for k in c) if k != "clips"]
    out: dict = {}
    for k in keys:
        if k.startswith("n_"):
            out[k] = int(sum(c.get(k, 0) for c in clips))
            continue
        num = den = 0.0
        seen = False
        for c in clips:
            v = c.get(k)
            if v is None or not isinstance(v, (int, float)) or math.isnan(v):
                continue
            w = float(c.get(_weight_key(k), c.get("n_frames", 1)))
            seen = True
            num, den = num + w * v, den + w
        out[k] = num / den if den > 0 else (0.0 if seen else float("nan"))
    out["clips"] = len(clips)
    out["frames"] = int(sum(c.get("n_frames", 0) for c in clips))
    return out


def _fmt(v) -> str:
    if v is None:
        return "-"
    return "nan" if isinstance(v, float) and math.isnan(v) else f"{v:.2f}"


def format_table(metrics: dict, ground_truth: dict | None = None, title: str = "ShapeMove evaluation",
                 name: str = "generated") -> str:
    """A plain-text table: metric, unit, better, ``name`` column and a ground-truth column."""
    rows = [(label, unit, better, _fmt(metrics.get(k)), _fmt(ground_truth.get(k)) if ground_truth else "-")
            for k, (label, unit, better, _) in METRICS.items() if k in metrics or (ground_truth and k in ground_truth)]
    head = ("metric", "unit", "better", name, "ground truth")
    widths = [max(len(str(r[i])) for r in rows + [head]) for i in range(5)]
    line = lambda r: "  ".join(str(c).ljust(w) if i < 3 else str(c).rjust(w) for i, (c, w) in enumerate(zip(r, widths)))  # noqa: E731
    n = f"{metrics.get('clips', 1)} clips, {metrics.get('frames', metrics.get('n_frames', 0))} frames at 20 fps"
    sep = "-" * len(line(head))
    return "\n".join([f"{title} ({n})", sep, line(head), sep] + [line(r) for r in rows] + [sep])


def print_table(metrics: dict, ground_truth: dict | None = None, **kwargs) -> None:
    print(format_table(metrics, ground_truth, **kwargs))


class PercentBar:
    """A ``progress(fraction, message)`` callback drawing a 0-100 % bar, opened at its first call (so
    after the bars the work opens before it, e.g. a classifier's); ``close()`` when the work is done."""

    def __init__(self, desc: str, quiet: bool = False):
        self.desc, self.quiet, self.bar = desc, quiet, None

    def __call__(self, fraction: float, message: str = "") -> None:
        if self.bar is None:
            from tqdm import tqdm

            self.bar = tqdm(total=100, desc=self.desc, unit="%", disable=self.quiet)
        self.bar.update(round(100 * fraction) - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def show_result(table: str, result: dict, json_path=None) -> int:
    """An evaluation command's ending: print its table, write ``result`` as JSON to ``json_path`` when
    given (NaN as null, atomically) and say where; the exit code 0."""
    print(table)
    if json_path:
        from pathlib import Path

        from ..atomic import atomic_write_json

        print(f"wrote {atomic_write_json(Path(json_path), result, nan_to_null=True)}")
    return 0


def run_and_show(desc: str, quiet: bool, run, format_results, json_path=None) -> int:
    """An evaluation command's run: ``run(progress)`` under a ``PercentBar`` named ``desc``, then
    ``show_result`` of ``format_results(result)``."""
    progress = PercentBar(desc, quiet)
    try:
        res = run(progress)
    finally:
        progress.close()
    return show_result(format_results(res), res, json_path)


def prompt_items(path, default, what: str, max_bytes: int) -> tuple:
    """(path, items) of a held-out prompt file ({"prompts": [...]} or a bare list), read with a size
    bound (``io.limits.read_json``); ``default`` when ``path`` is None; items [] when not a list."""
    from pathlib import Path

    from ..io.limits import read_json

    path = Path(path) if path else Path(default)
    doc = read_json(path, what, max_bytes)
    items = doc.get("prompts") if isinstance(doc, dict) else doc
    return path, items if isinstance(items, list) else []


def add_output_arguments(p) -> None:
    """An evaluation command's ``--json`` (write the results there) and ``--quiet`` (no progress bar)."""
    from pathlib import Path

    p.add_argument("--json", type=Path, default=None, help="write the results here")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def checked_seconds(seconds, lo: float, hi: float = 60.0):
    """``seconds`` (None: the product's length) when within lo..hi, else a ShapeMoveError naming it."""
    from ..errors import ShapeMoveError

    if seconds is not None and not lo <= seconds <= hi:
        raise ShapeMoveError(f"--seconds must be between {lo:g} and {hi:g}, got {seconds}")
    return seconds
