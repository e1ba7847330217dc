"""A user's own clip, chosen for a prompt, played as it was captured when the codec cannot carry it.

``generate --library DIR`` (and the Generate panel's "Use Library motions") adds the user's
captioned motions to the retrieval memory (``Generator.add_library``): a clip whose caption is near
the prompt joins best-of-N's candidates as windows of its SA-VAE codes (``retrieved_candidates.py``).
Decoded, those codes flatten what the codec cannot carry: the user's own captured kick comes back
as a raised knee (docs/codec.md, "Which actions the codec keeps"). Retargeting measures that before it
moves a take (``take_fidelity.py``), and a library window is measured the same way: its codes
decoded on the clip's own body against the clip's own frames of that window (``window_fit``). Where
the worst second misses by more than ``LOST_TAKE_MM``, the window is what the rig would play as
captured: the TMA picks among the candidates by those captured frames, and a window it keeps is
moved onto the requested body by its own rotations with its feet planted (``captured_window``,
``retarget.planted_retarget``), with a note (``Motion.notes``). A window the codes carry is decoded
as any candidate.

    take = read_take(path, body)                          # the clip on its own body (builder arrays)
    fit = window_fit(take, clip_codes, window, vae)       # None: the codes carry it
    motion = captured_window(take, fit, body, betas, path.name)
"""
from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..scene.motion_file import Motion
from .take_fidelity import LOST_TAKE_MM, worst_take_error_mm


class WindowFit(NamedTuple):
    lo: int            # the window's first frame in the take
    hi: int            # one past its last (4 frames a code)
    worst_mm: float    # its codes' worst second against the take, on the take's own body


def window_start(clip_codes, window) -> int | None:
    """Where ``window`` (codes cut from a clip, ``retrieved_candidates.windows``) starts in the
    clip's ``clip_codes``; None when it is not a slice of them."""
    c, w = [int(x) for x in clip_codes], [int(x) for x in window]
    n = len(w)
    if n == 0 or n > len(c):
        return None
    for s in range(len(c) - n + 1):
        if c[s:s + n] == w:
            return s
    return None


def read_take(path, body, ik_refine_iters: int = 10) -> dict:
    """A library file as the dataset builder reads a clip, on its subject's own body
    (``ClipProcessor.process``: rotations, root, contacts, shape-aware features, fitted betas)."""
    from ..search.motion_search import library_clip
    from .retarget import processor, source_joints

    joints, _ = source_joints(library_clip(Path(path)), body)
    return processor(body, ik_refine_iters).process(joints)


def window_fit(take: dict, clip_codes, window, vae, fallback_mm: float = LOST_TAKE_MM) -> WindowFit | None:
    """The frames of ``window`` (codes of the clip whose memory codes are ``clip_codes``) in the
    take ``read_take`` gave, when its codes decoded on the take's own body miss those frames by more
    than ``fallback_mm`` in their worst second; None when they carry them or the window cannot be
    placed."""
    start = window_start(clip_codes, window)
    if start is None:
        return None
    down = vae.cfg.downsample
    lo, hi = start * down, (start + len(window)) * down
    if hi > len(take["new_joint_vecs"]):
        return None
    worst = worst_take_error_mm(window, vae, take["betas"], take["new_joint_vecs"][lo:hi])
    return WindowFit(lo, hi, worst) if worst > fallback_mm else None


def captured_window(take: dict, fit: WindowFit, body, betas, name: str, ik_refine_iters: int = 10) -> Motion:
    """The take's frames [fit.lo, fit.hi) on the body ``betas`` by its own rotations, feet planted,
    starting at the origin facing +Z (``retarget.planted_retarget``), with a note naming ``name``."""
    from .retarget import planted_retarget

    part = {**take, **{k: np.asarray(take[k])[fit.lo:fit.hi] for k in ("rotations", "root", "contacts")}}
    out = planted_retarget(part, body, betas, ik_refine_iters)
    out.notes.append(f"played as captured from your library ({name}): its codes miss it by {fit.worst_mm:.0f} mm "
                     "in its worst second")
    return out
