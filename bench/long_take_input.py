"""A long capture session built from a short real clip: the input of the long-take benchmark and tests.

``write_long_take(src, out, seconds, fps)`` repeats the data rows of a real BVH (a Bandai walk) until
the take lasts ``seconds``, as one continuous walk: each repetition's world translation (the
channels of the joint that carries it, Bandai's ``Hips``) continues where the previous one ended
(X/Z only, so the walker keeps walking and never jumps back), rotations are unwrapped over time,
and the take is resampled to ``fps`` by linear interpolation of the channel values (30 fps Bandai ->
120 fps). The hierarchy is the source's, byte for byte; the result is a valid BVH a user could have.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.atomic import atomic_path
from ..core.io.bvh import parse_bvh
from ..core.io.limits import read_text

WALK = "dataset-2_walk_masculine_003"  # 220 frames at 30 fps (7.3 s), a straight walk


def walk_path(root: Path) -> Path:
    """The Bandai walk inside a ``mocap_root`` folder."""
    return Path(root) / "bandai" / "dataset-2" / "data" / f"{WALK}.bvh"


def long_take_rows(src, seconds: float, fps: float) -> tuple[str, np.ndarray, float]:
    """(hierarchy text up to MOTION, (T,C) channel rows, frame time) of the long take."""
    src = Path(src)
    text = read_text(src, "BVH")
    head = text[:text.index("MOTION")]
    names, parents, offsets, channels, data, dt = parse_bvh(text, src)
    # the joint whose position channels move through the world: the one whose X/Z travel most
    col, best, travel = 0, None, -1.0
    for chans in channels:
        cols = {c: col + i for i, c in enumerate(chans)}
        col += len(chans)
        if "xposition" in cols and "zposition" in cols:
            t = float(np.ptp(data[:, cols["xposition"]]) + np.ptp(data[:, cols["zposition"]]))
            if t > travel:
                best, travel = (cols["xposition"], cols["zposition"]), t
    rot_cols = [i for i, c in enumerate(c for chans in channels for c in chans) if c.endswith("rotation")]
    one = data.copy()
    one[:, rot_cols] = np.degrees(np.unwrap(np.radians(one[:, rot_cols]), axis=0))
    n_src = len(one)
    reps = int(np.ceil(seconds / (dt * (n_src - 1)))) + 1
    step = one[-1] - one[0]  # what one repetition adds: translation (X/Z) and unwrapped turns
    keep = np.zeros(one.shape[1], bool)
    keep[list(best or ())] = True
    keep[rot_cols] = np.abs(step[rot_cols]) > 180  # whole turns only continue; wobble does not drift
    rows = np.concatenate([one[:-1] + k * np.where(keep, step, 0.0) for k in range(reps)], 0)
    t_src = np.arange(len(rows)) * dt
    n_out = int(round(seconds * fps)) + 1
    t_out = np.arange(n_out) / fps
    out = np.stack([np.interp(t_out, t_src, rows[:, c]) for c in range(rows.shape[1])], 1)
    return head, out, 1.0 / fps


def write_long_take(src, out, seconds: float, fps: float = 30.0) -> Path:
    """Write the long take (see the module docstring) to ``out`` (.bvh), atomically."""
    head, rows, ft = long_take_rows(src, seconds, fps)
    out = Path(out)
    with atomic_path(out) as tmp, open(tmp, "w") as fh:
        fh.write(head + f"MOTION\nFrames: {len(rows)}\nFrame Time: {ft:.7f}\n")
        for i in range(0, len(rows), 4096):
            np.savetxt(fh, rows[i:i + 4096], fmt="%.5g")
    return out
